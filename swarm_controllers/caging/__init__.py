"""Collective transport by caging (Cardoso, Nedjah & Mourelle; ../shared/papers/caging_transport.md).

`world_config` (the ``transport`` world section: the object, the landmark grid), `config` (the
``controller.caging`` section, Table 1), `geometry` (eqs. (1), (2), (5) and the
route to a cage position), `motion` (the PIDs and the state machines of Fig. 1), `protocol`
(messages of types 0-4), `behaviour` (Algs. 3-6), `metrics` (stage times, trajectory error,
whether the cage held) and `figures` (the object's path over the planned path, cage snapshots).
"""
