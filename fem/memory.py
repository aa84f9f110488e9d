"""Whether a pair-FE body fits in this machine's memory, decided before it is meshed.

Why: the pair FE meshes the whole gear, its blank at the interior size h_g = 0.4 m
(``fem.pair_model.body_sizes``), so a large solid blank is millions of dofs. The
100/500-tooth solid-blank corner of the atlas (m 3 mm, bores 0.2 r_f) meshed for minutes,
held 16 GB and was stopped after 33 min without a result (benchmarks/bench_atlas.py). Such
a body is now refused in one line, before Gmsh runs, with the estimate and what to change.

The estimate (fitted on this machine by benchmarks/bench_fem_memory.py, which writes the
data and the fit to benchmarks/results/bench_fem_memory.json):

    elements   N_e = A_body / (a h_g^2) + C_TEETH A_teeth / (a h_far^2)
                     + C_CONTACT L / (a g h_c) + N_TOOTH0,                     a = sqrt(3) / 4
    dofs       n = DOFS_PER_ELEMENT N_e
    memory     M = M0 + C_FILL sum_b n_b log2 n_b                                 [bytes]

A_body = pi (r_f^2 - r_bore^2) is the blank (bore to root circle), meshed at h_g (an
equilateral triangle of side h has area a h^2); A_teeth is the outline's area outside the
root circle, at the far-tooth size h_far and finer near the fillets and the near teeth
(C_TEETH); along tooth 0's refined flank (length L, size h_c = a_ref / 2.5, which falls with
the load) the size grows as h_c + g d away from it, so that band holds
int L / (a (h_c + g d)^2) dd ~ L / (a g h_c) elements (C_CONTACT); N_TOOTH0 is the rest of
the near teeth's refinement. Quadratic (P2) triangles have about
two nodes per element, two dofs each. The memory is the peak of the process: interpreter
and libraries (M0) plus the sparse factors of the bodies b the run builds, each of whose
fill under nested dissection grows like n log n on a 2D mesh (George, SIAM J. Numer. Anal.
10, 1973). The sum, not the largest body: two distinct bodies are built at the same time
(fem.pair_model overlaps the first one's factorization with the second one's build), so
both factors can be resident at once; how much they overlap depends on the timing (the
40/80 high-contact-ratio corner peaked at 875 to 929 MB in three runs of the same code),
so the model counts both.
A pair of equal gears builds one body. Fitted on the 17 bodies that mesh here of the seven
atlas corners (200 N/mm) and of two light loads (the paper pair at 40 N m, the 23/47 corner
at 20 N/mm), 0.05 to 1.6 M dofs: the estimated dofs within 6 % of the real meshes'; the
peak, by least squares on the relative error, within 6.4 % of the 7 FE runs of the last
bench_atlas.py run and 10.6 % of the run before, whose 40/80 corner peaked at 929 MB (the
peaks move by a few % from run to run). The former model, the larger body alone (M0 326
MiB, c 171 B), missed the run before's peaks by up to 15.5 % (the 40/80 corner: 785 MB
modelled) and the last run's by 10.3 %. The 100/500 solid-blank corner is estimated at
11.8 M dofs and about 42 GB.

The budget is ``GEARWEAR_FE_MEMORY_GB`` (GB = 1e9 bytes) if set, else BUDGET_FRACTION of
the machine's physical memory. It is per process: FE designs running side by side (an
atlas on N workers) each get the whole budget, so give N workers a budget of about
1/N of the memory.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence

from gearwear.core.validation import InputError, fail

#: elements per equilateral-triangle area of the far-tooth size in the teeth region
C_TEETH = 2.2
#: elements of the graded band along tooth 0's refined flank, per L / (a g h_c)
C_CONTACT = 1.6
#: elements of the near teeth's extra refinement (fillets, near size)
N_TOOTH0 = 4800
#: dofs per P2 triangle (2 per node, ~2.1 nodes per element; 4.09-4.23 on the 14 bodies)
DOFS_PER_ELEMENT = 4.2
#: peak memory of a process that builds bodies of n_b dofs: M0 + C_FILL sum_b n_b log2 n_b (bytes)
M0_BYTES = 216 * 2**20
C_FILL_BYTES = 146.0
#: the share of physical memory one FE process may use when GEARWEAR_FE_MEMORY_GB is unset
BUDGET_FRACTION = 0.8
ENV = "GEARWEAR_FE_MEMORY_GB"


def body_dofs(
    outline_area_m2: float,
    root_radius_m: float,
    bore_radius_m: float,
    global_m: float,
    far_m: float,
    flank_m: float = 0.0,
    contact_m: float = 1.0,
    growth: float = 0.25,
) -> float:
    """Estimated dofs of a pair-FE body (see the module docstring): the outline's polygon
    area (m^2, the whole toothed disc), the root circle and the bore (m), the interior and
    far-tooth element sizes (m), and tooth 0's refined flank: its length (m), its element
    size h_c (m) and the size gradient away from it."""
    a = math.sqrt(3.0) / 4.0
    body = math.pi * (root_radius_m**2 - bore_radius_m**2)
    teeth = max(outline_area_m2 - math.pi * root_radius_m**2, 0.0)
    contact = flank_m / (a * growth * contact_m)
    elements = body / (a * global_m**2) + C_TEETH * teeth / (a * far_m**2) + C_CONTACT * contact + N_TOOTH0
    return DOFS_PER_ELEMENT * elements


def peak_bytes(dofs: float | Sequence[float]) -> float:
    """Estimated peak memory (bytes) of a pair-FE run that builds bodies of ``dofs`` dofs
    (one number: one body; a sequence: the distinct bodies built together, see the module
    docstring)."""
    try:
        ns = [max(float(dofs), 2.0)]  # type: ignore[arg-type]
    except TypeError:  # a sequence
        ns = [max(float(n), 2.0) for n in dofs]  # type: ignore[union-attr]
    return M0_BYTES + C_FILL_BYTES * sum(n * math.log2(n) for n in ns)


def budget_bytes() -> float:
    """The memory one FE process may use (bytes): ``GEARWEAR_FE_MEMORY_GB`` x 1e9, else
    BUDGET_FRACTION of the physical memory. A bad value of the variable is an InputError."""
    raw = os.environ.get(ENV)
    if raw is not None and raw.strip():
        try:
            gb = float(raw)
        except ValueError:
            gb = math.nan
        if not (math.isfinite(gb) and gb > 0):
            raise InputError(f"{ENV} = {raw!r}: must be a number of GB > 0 (the memory one FE process may use)")
        return gb * 1e9
    return BUDGET_FRACTION * os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def check_bodies(bodies: Sequence[tuple[int, str, int, float, float]]) -> None:
    """A one-line InputError if the distinct bodies a pair-FE run builds, ``bodies`` =
    (gear index, gear name, teeth, bore radius m, estimated dofs) each, would need more than
    :func:`budget_bytes` together (:func:`peak_bytes` of all their dofs). The line names the
    bore of the largest body: the one a larger bore shrinks most."""
    need, have = peak_bytes([b[4] for b in bodies]), budget_bytes()
    if need <= have:
        return
    gear_index, gear_name, teeth, bore_radius_m, dofs = max(bodies, key=lambda b: b[4])
    source = f"{ENV}" if os.environ.get(ENV, "").strip() else f"{BUDGET_FRACTION:.0%} of this machine's memory"
    both = " (with the other gear's body, built at the same time)" if len(bodies) > 1 else ""
    raise fail(
        f"hub_radius_m[{gear_index}]",
        bore_radius_m,
        "m",
        f"the pair FE's body of the {gear_name} ({teeth} teeth, its blank meshed at 0.4 module) would have about "
        f"{dofs / 1e6:.3g} M dofs and need about {need / 1e9:.2g} GB{both}, more than the {have / 1e9:.2g} GB it "
        f"may use ({source}); a larger bore (a rim) shrinks it, or use an analytic stiffness method",
    )
