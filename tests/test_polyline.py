"""geometry.polyline and geometry.sampling against hand-computable cases: projection
onto the unit square, stitching, quadratic edges on y = x^2, and the resampled
profile's circle arcs (root and tip lands: every point on the circle, equal steps
of at most the requested spacing, junctions kept)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearwear.geometry.polyline import (
    cumulative_length,
    project_to_polyline,
    quadratic_eval,
    quadratic_parameter,
    quadratic_points,
    stitch,
    with_midpoints,
)
from gearwear.geometry.profile import FILLET, INVOLUTE, ROOT_LAND, TIP_LAND, gear_outline, tooth_outline, tooth_profile
from gearwear.geometry.sampling import region_junctions, resample_profile
from gearwear.geometry.spec import default_pair

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]])


def test_projection_onto_the_unit_square():
    pts = np.array(
        [
            [0.5, -0.2],  # below the bottom edge
            [1.3, 0.4],  # right of the right edge
            [0.2, 0.5],  # inside, nearest to the left edge
            [1.2, 1.2],  # beyond the corner (1, 1)
            [0.0, 0.0],
        ]
    )  # on the first vertex
    pr = project_to_polyline(pts, SQUARE)
    assert pr.segment.tolist() == [0, 1, 3, 1, 0]
    assert np.allclose(pr.t, [0.5, 0.4, 0.5, 1.0, 0.0], rtol=0, atol=1e-15)
    assert np.allclose(pr.distance, [0.2, 0.3, 0.2, math.sqrt(0.08), 0.0], rtol=0, atol=1e-15)
    assert np.allclose(pr.s, [0.5, 1.4, 3.5, 2.0, 0.0], rtol=0, atol=1e-15)
    far = project_to_polyline(np.array([[5.0, 5.0], [0.5, 1.05]]), SQUARE, max_distance=0.1)
    assert far.distance[0] == np.inf and far.distance[1] == pytest.approx(0.05, abs=1e-15)
    assert cumulative_length(SQUARE).tolist() == [0.0, 1.0, 2.0, 3.0, 4.0]


def test_stitch_keeps_shared_points_once():
    a = np.array([[0.0, 0.0], [1.0, 0.0]])
    b = np.array([[1.0, 0.0], [1.0, 1.0]])
    c = np.array([[1.0, 1.0], [0.0, 0.0]])
    assert stitch([a, b]).tolist() == [[0, 0], [1, 0], [1, 1]]
    assert stitch([a, b, c], closed=True).tolist() == [[0, 0], [1, 0], [1, 1]]
    with pytest.raises(ValueError, match="starts at"):
        stitch([a, c])
    with pytest.raises(ValueError, match="do not close"):
        stitch([a, b], closed=True)


def test_quadratic_edge_on_a_parabola():
    """The quadratic through (-1, 1), (0, 0), (1, 1) at t = 0, 1/2, 1 is y = x^2 with
    x = 2 t - 1: the point (x, x^2) has t = (x + 1) / 2 and tangent (1, 2 x) / |.|."""
    chain = np.array([[-1.0, 1.0], [0.0, 0.0], [1.0, 1.0], [2.0, 1.0], [3.0, 1.0]])  # + a straight edge
    x = np.array([-0.8, 0.0, 0.5])
    t = quadratic_parameter(np.column_stack([x, x * x]), *(np.repeat(chain[i : i + 1], 3, axis=0) for i in (0, 1, 2)))
    assert np.allclose(t, (x + 1) / 2, rtol=0, atol=1e-14)
    # off the curve along the normal at (0.5, 0.25) (tangent (1, 1) / sqrt 2), on the convex side
    off = np.array([[0.5, 0.25]]) + 0.1 * np.array([[1.0, -1.0]]) / math.sqrt(2)
    assert quadratic_parameter(off, chain[:1], chain[1:2], chain[2:3])[0] == pytest.approx(0.75, abs=1e-14)
    xy, tan = quadratic_eval(chain, np.array([0.75, 1.5]))
    assert np.allclose(xy, [[0.5, 0.25], [2.0, 1.0]], rtol=0, atol=1e-15)
    assert np.allclose(tan, [[1 / math.sqrt(2), 1 / math.sqrt(2)], [1.0, 0.0]], rtol=0, atol=1e-15)
    pts = quadratic_points(chain, 4)
    assert len(pts) == 9 and np.allclose(pts[:5, 1], pts[:5, 0] ** 2, atol=1e-15)
    assert with_midpoints(np.array([0.0, 1.0, 3.0])).tolist() == [0.0, 0.5, 1.0, 2.0, 3.0]


@pytest.fixture(scope="module")
def profile():
    return tooth_profile(default_pair().gear(0), sag_m=1e-9)


@pytest.mark.parametrize("midpoints", [False, True])
def test_resampled_lands_stay_on_their_circles_at_the_spacing(profile, midpoints):
    """Root land (r_f) and tip land (r_a) are circle arcs: every resampled point lies
    on its circle to within the source sag (1 nm), the arc steps are equal and at
    most the requested spacing, and the junctions (root/fillet tangency, tip
    corner) are points of the resampled profile."""
    g = profile.gear
    h = {ROOT_LAND: 0.3e-3, FILLET: 0.2e-3, INVOLUTE: 0.5e-3, TIP_LAND: 0.25e-3}
    rp = resample_profile(profile, h, midpoints=midpoints)
    step = 2 if midpoints else 1
    for region, radius in ((ROOT_LAND, g.root_radius_m), (TIP_LAND, g.tip_radius_m)):
        sel = rp.region == region
        if region == TIP_LAND:  # the tip corner is labelled INVOLUTE (last involute point)
            sel |= np.arange(len(sel)) == np.flatnonzero(rp.region == INVOLUTE)[-1]
        assert np.max(np.abs(np.hypot(*rp.xy[sel].T) - radius)) < 1.5e-9
        # the arc length on the circle between successive points is the step in s
        ang = np.arctan2(rp.xy[sel, 0], rp.xy[sel, 1])
        ds = np.diff(rp.s[sel])
        assert np.allclose(radius * np.abs(np.diff(ang)), ds, rtol=1e-6)
        steps = np.diff(rp.s[sel][::step])
        assert np.all(steps <= h[region] * (1 + 1e-9)) and np.ptp(steps) < 1e-12
        n = math.ceil((rp.s[sel][-1] - rp.s[sel][0]) / h[region] - 1e-9)
        assert len(steps) == n
    src_junctions = profile.xy[region_junctions(profile)]
    for p in src_junctions:
        assert np.min(np.hypot(*(rp.xy - p).T)) < 1e-15
    if midpoints:  # mid-points halve the arc length of every step
        assert np.allclose(rp.s[1::2], 0.5 * (rp.s[0:-1:2] + rp.s[2::2]), rtol=0, atol=1e-15)


def test_outlines_stitch_teeth_and_keep_quadratic_chains(profile):
    """One tooth: right flank, tip-axis point once, mirrored left flank; the gear:
    z teeth, shared space centres once, closed without a repeated point. A quadratic
    chain (odd length) stays one: vertices at even positions."""
    z = profile.gear.teeth
    n = len(profile.xy)
    t = tooth_outline(profile)
    assert len(t) == 2 * n - 1
    assert np.allclose(t[n - 1 :][::-1] * [-1, 1], profile.xy, rtol=0, atol=1e-18)
    assert len(gear_outline(profile)) == z * (2 * n - 2)
    chain = resample_profile(profile, {r: 1e-3 for r in (ROOT_LAND, FILLET, INVOLUTE, TIP_LAND)}, midpoints=True)
    tq = tooth_outline(chain)
    assert len(tq) % 2 == 1 and np.allclose(tq[0::2][: len(chain.xy[0::2])], chain.xy[0::2])
