"""The stiffness tables of a sweep's points, each computed once per worker process.

A sweep point builds its scene from scratch, and with it the k_h(phi), e(phi) tables
(gearwear.jobs.simulate.stiffness_input: the Ishikawa load sharing, ~20-60 ms for the
paper pair; an FE table far more). Most swept keys do not change them: the speed, the
damping, the bodies, the solver or the bearing clearance without the static
centre-distance coupling enter the dynamics only. The tables depend on nothing but the
source's :class:`gearwear.stiffness.sources.Request` (pair, torque, operating clearance,
wear, flank, faults, nodes, plane, breakpoints, blank torsion, a table's own values), so
that request, the source's name with it, is the key: two points with the same request get
the same curve, whatever else differs between them.

The key is the request's pickle: equal requests built the same way (a fresh scene per
point) pickle to the same bytes; a request that pickles differently is only a miss, never
a wrong table. The cached curve's arrays are made read-only, so a caller that wrote into
a table shared with later points would fail at once instead of changing them.
"""

from __future__ import annotations

import pickle
from collections import OrderedDict
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from gearwear.analytic.tvms import MeshStiffness
    from gearwear.stiffness.sources import Request

#: distinct requests kept per process (a sweep of torques or wear has one per value; the
#: paper pair's table is ~50 kB, an FE one a little more)
MEMO_SIZE = 32


class TableMemo:
    """``memo(source, request)``: :func:`gearwear.stiffness.sources.curve`, computed once per
    distinct (source, request) and kept for the last MEMO_SIZE of them. ``hits`` and
    ``misses`` count the calls."""

    def __init__(self, size: int = MEMO_SIZE):
        self.size = size
        self._store: OrderedDict[bytes, MeshStiffness] = OrderedDict()
        self.hits = 0
        self.misses = 0

    def __call__(self, source: str, request: Request) -> MeshStiffness:
        from gearwear.stiffness.sources import curve

        try:
            key = pickle.dumps((source, request), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:  # a request holding something unpicklable (an FE executor): not memoised
            self.misses += 1
            return curve(source, request)
        found = self._store.get(key)
        if found is not None:
            self._store.move_to_end(key)
            self.hits += 1
            return found
        self.misses += 1
        r = curve(source, request)
        for name in ("angle_rad", "k_N_per_m", "excitation_m"):
            a = getattr(r, name, None)
            if isinstance(a, np.ndarray):
                a.setflags(write=False)
        self._store[key] = r
        while len(self._store) > self.size:
            self._store.popitem(last=False)
        return r

    def clear(self) -> None:
        self._store.clear()
        self.hits = self.misses = 0
