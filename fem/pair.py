"""Spur-pair mesh stiffness by resolved FE contact of the two gear bodies: loaded
static transmission error and mesh stiffness over one mesh period, any pair
(unequal teeth, profile shift, wear, clearance-shifted centre distance), and over one
revolution of the faulty gear with a spall or a root crack on one tooth.

Model (SI units: m, N, rad, Pa)
-------------------------------
Each distinct gear is one full FE body (fem.pair_body: all z teeth, P2 triangles,
plane stress by default, thickness = face width b, bore fixed) whose tooth 0 has
its drive flank refined to the contact element size h_c = a_ref / 2.5 (a_ref: Hertz
half-width of one pair at the pitch point under the full load, 64 um for the paper
pair at 40 N m) over the whole candidate range, from below the start of active
profile up to and including the tip corner. The flexibility G of those flank nodes
(and of the neighbouring teeth's drive flanks) comes from one sparse factorization
per body by static condensation; rotational periodicity maps every engaged tooth to
tooth 0 (a load on tooth t_l read on tooth t_k = a load on tooth 0 read on tooth
t_k - t_l). No analytic local (Hertz/Weber) term enters: the contact zone is
resolved by the mesh.

The pieces (each module one idea)
---------------------------------
* geometry.pair_positions  the fixed frame (pinion centre O1 = 0, line of action along +x
  from T1 = (0, r_b1) to T2 = (L, r_b1), gear centre O2 = (L, r_b1 + r_b2)), the tooth
  frames of a pair at LOA position d (both nominal flanks through (d, r_b1); pinion slot j
  on tooth -j, gear slot j on tooth +j), the exact normal gap between involutes, and which
  slots can touch. The driven gear is held; the pinion turns by the extra angle dtheta,
  and the loaded STE is delta = r_b1 dtheta.
* fem.pair_body            the gear bodies: mesh, flexibility of the drive flanks by static
  condensation, the blank's reading.
* fem.pair_model           the pair model (:func:`pair_model`): inputs, element sizes,
  bodies (cached in-process), wear and flank-deviation depths.
* fem.pair_candidates      contact candidates of one pair at one position: exact gaps (wear,
  spall), lever arms, rigid gap.
* fem.pair_position        the contact problem at one pinion angle (:func:`solve_position`)
  and the blanks' rotations.
* fem.pair_cycle           the positions of a period or a revolution and the mesh stiffness
  curve (:func:`pair_contact`), in process or on an executor; extended contact widths.
* fem.pair_result          the result, :class:`PairFE`.
* fem.pair_centre_line     centre-line readings in single contact (c_1, c_2, c_local).
* fem.pair_fields          displacement and stress fields as VTU.

The FE-versus-analytic consistency check (c_local against Weber's formula, the identity
k_pair = 1 / (c_1 + c_2 + c_local) with the single-tooth FE) is the app's:
gearwear.stiffness.comparison.pair_consistency.

The blank's torsion
-------------------
Each body is held at its bore, so delta (and k) holds the torsion of both blanks
between bore and teeth: moving the bores of the 23/47 pair (m 3, b 30 mm) from 12.5/25
to 24/55 mm moves the mean by +46 % while the analytic models have no such term. It is
reported as its own term. Reference circle of gear i: r_ref = r_f - 2 m, not below the
bore (pair_body.blank_reference_radius_m: there the tooth-pitch part of a tooth load's
field has decayed to ~exp(-4), so the circle turns as a rigid ring; with a thinner rim
r_ref is the bore, there is no blank term and the whole rim stays in the mesh
stiffness). Its rotation theta_ref,i (counter-clockwise) is the least-squares rigid
rotation of 16 z points on it, i.e. the mean tangential displacement over r_ref
(pair_body.blank_reading: a functional a_i of the body's displacement, exact for a
rigid rotation). By reciprocity theta_ref,i = a_i . K_i^-1 f_i = h_i . f_i with
h_i = (K_i^-1 a_i) on the condensed flank dofs: one more solve per body with the
factors of the condensation, nothing per position. Per position

    delta = delta_mesh + r_b1 theta_ref,1 + r_b2 theta_ref,2

(the pinion's contact moment turns its circle back against the drive, the gear's turns
its circle on with it: both widen the approach), and the mesh-only curve is the secant
of fem.pair_cycle with delta_mesh: k_mesh = sum F_k / (delta_mesh - g_k); its tangent is
1 / (1 / k_tangent - (r_b1 theta_1 + r_b2 theta_2) / F). Each blank's torsional
stiffness is k_blank,i = T_i / theta_ref,i (N m/rad), T_i the contact loads' moment
about the gear's centre (T_1 = T; T_2 = T z2 / z1 to the off-line-of-action arms). The
mean (n = 0 Fourier part) of u_theta of a solid annulus held at the bore and loaded
outside r_ref obeys u'' + u'/r - u/r^2 = 0 with the torque through every circle, so
k_blank = 4 pi G b / (1 / r_bore^2 - 1 / r_ref^2) exactly (in-plane shear: plane
stress and plane strain alike), whatever the teeth do; the FE gives it to 1e-4
(tests/test_blank_torsion.py) and the identity STE / F = STE_mesh / F + r_b1^2 / k_1 +
r_b2^2 / k_2 with the closed-form k holds to 3e-4. What stays in the mesh-only term is
everything but the n = 0 part below r_ref: the blank's bending under the net tooth
force (n = 1, ~ ln(r_ref / r_bore)) and the teeth's foundation, which a bore close
below the root stiffens (bore study, benchmarks/bench_bore_study.py: the mesh-only mean
moves +23 % from 12.5/25 to 24/55 mm bores, against +46 % bore-fixed; between the thick
rims of 8/16 and 12.5/25 mm it moves ~4 %). Which to compare: Ishikawa (tooth clamped at
the root), the energy method (Sainsot's foundation is the body's local deformation
below the tooth, bore-dependent through h_fi = r_f / r_bore but without a rigid torsion
of the blank) and ISO 6336 (c' of solid blanks, no bore in it) with the mesh-only
curve; a 6-DOF model without shaft or blank torsion of its own with the bore-fixed one.

Faults on one tooth (geometry.faults)
-------------------------------------
Numbering as geometry.faults: in mesh period n of a revolution, slot j holds the pair
that entered n - j periods after tooth pair 0, so the faulty tooth tau of gear g sits
in slot j when (n - j) mod z_g = tau. The curve spans revolution_periods mesh periods
(z of the faulty gear; lcm with faults on both gears), ``positions`` per period. A
position is solved again only where a slot holding a faulty tooth is a candidate pair
(within EXTENSION_PITCHES p_b of the path, so the corner contact is included); every
other position is the healthy period's, copied (rotational periodicity), so those
periods are the healthy curve to the bit. The faulty solves use the healthy period's
angles, with ``period`` telling which slot holds the faulty tooth.

* Spall: the pit (through the face width, from its start diameter along the involute
  for its length, ``depth`` deep) is a flank depth of the faulty tooth only: the gap of
  a slave node inside it, or of a slave node whose foot on the master lies inside it,
  grows by the depth. Its two edges are corners of the spalled flank: exact points on
  the involute at the edge radii, candidates like the tip corner, loaded through the
  P2 edge weights, against the mating involute (flank nodes within h_c / 4 of an edge
  give way to it). Where the contact point lies within a window of the pit, the
  candidate window reaches past both edges. No bridging formula enters: at near-zero
  load the mating flank rests on the edges, and the TE is the rigid gap of the exact
  geometry (~ min(depth, x^2 / (2 R')), geometry.faults.spall_gap_m).
* Crack: a second body of the cracked gear (pair_body.build_cracked_body): the straight
  crack of geometry.crack cut into tooth 0 by Gmsh's Crack plugin (both faces free, no
  face contact), the tip refined to CRACK_TIP_FRACTION x min(fillet size, depth) as in
  fem.tooth (default_crack_tip_size_m, with the body's fillet size), and the drive
  flanks of the teeth that can be candidates together with the cracked one
  (geometry.pair_positions.fault_neighbours: floor(epsilon + 2 EXTENSION_PITCHES) each side) refined alike and
  condensed over the radius range they reach meanwhile. At a position where
  the cracked tooth is a candidate, that gear's flexibility comes from the cracked body,
  every candidate read and loaded on its own tooth relative to the cracked one (no
  periodic mapping); the mating gear keeps its healthy body. Elsewhere the healthy body
  serves (the crack's effect on its neighbours' compliance when it is not engaged is
  left out).

Measured (paper pair, 40 N m, 24 positions per period; wall times: make bench): spall
example (1 mm x 20 um at 150 mm on pinion tooth 0): 67 positions solved of 720, 38-268
candidates per position; root crack example (2 mm at 45 deg on pinion tooth 0): cracked
body 129k dofs, 3128 condensed dofs. Checks (tests/test_fem_faults.py):
near-zero-load TE over a short pit = spall_gap_m to 0.70 % of its peak; in single contact
on the cracked tooth c_1 read in the cracked pair = single-tooth FE of the cracked tooth
to 0.05-0.06 %, and the pair compliance = c_1,cracked + c_2 + c_local,healthy to
0.14-0.24 % (the crack also raises c_local by 0.3-0.7 %).

Measured (benchmarks/bench_fem_pair.py, 40 N m, plane stress, P2; wall times there)
-----------------------------------------------------------------------------------
Paper pair, 24 positions, h_c = 25.6 um: 96k dofs, 2172 condensed dofs, 38-77
candidates per position. Mean 3.3838e8 N/m; single-pair plateau 2.4686e8, double-pair
plateau 3.7784e8 N/m; loaded corner contact 0.298 deg before A and 0.296 deg after
E. Contact-zone refinement h_c = a/1.25 .. a/5: mean 3.38755, 3.38530, 3.38378,
3.38359, 3.38351 e8 (one more refinement of the default: -0.006 %; Richardson
estimate 3.38347e8). Single contact: c_1, c_2 equal the single-tooth FE to 0.1-0.15 %,
k_pair = 1 / (c_1 + c_2 + c_local) to 0.09 %, c_local = 1.50e-9 m/N is 4.5 % above
Weber in plane stress and 15 % above Weber in plane strain (gearwear.stiffness.comparison.pair_consistency).
Shifted 21/37 pair (x = +0.25/-0.10): two bodies, mean 3.2486e8,
plateaus 2.4752e8 / 3.7265e8 N/m, corner contact 0.461 / 0.463 deg.
"""

from __future__ import annotations

from .pair_centre_line import centre_line_compliance
from .pair_cycle import extended_contact_widths, pair_contact
from .pair_fields import write_fields
from .pair_model import (
    ELEMENTS_PER_HALF_WIDTH,
    EXTENSION_PITCHES,
    WINDOW_HALF_WIDTHS,
    PairModel,
    body_sizes,
    pair_model,
)
from .pair_position import PositionSolution, blank_rotations, solve_position
from .pair_result import PairFE

__all__ = [
    "PairFE",
    "PairModel",
    "PositionSolution",
    "pair_contact",
    "pair_model",
    "solve_position",
    "blank_rotations",
    "body_sizes",
    "extended_contact_widths",
    "centre_line_compliance",
    "write_fields",
    "ELEMENTS_PER_HALF_WIDTH",
    "WINDOW_HALF_WIDTHS",
    "EXTENSION_PITCHES",
]
