"""Run traces and metrics: built live by the batch runner or replayed from a bag."""
