"""Byte strings for the codecs' fuzz tests (test_codecs.py, test_sensing.py)."""

from __future__ import annotations

from hypothesis import strategies as st


def fuzzed(valid: bytes, data: st.DataObject, max_size: int) -> tuple[bytes, bytes]:
    """`valid` with 1-4 bytes past its encapsulation header overwritten, and a byte string of at
    most `max_size` bytes drawn from nothing."""
    mutated = bytearray(valid)
    for _ in range(data.draw(st.integers(1, 4))):
        mutated[data.draw(st.integers(4, len(valid) - 1))] = data.draw(st.integers(0, 255))
    return bytes(mutated), data.draw(st.binary(max_size=max_size))
