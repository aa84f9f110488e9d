"""Tooth profiles resampled at chosen arc-length positions (SI units, m).

A :class:`~gearwear.geometry.profile.ToothProfile` from ``tooth_profile`` is a fine
polyline (chord sag ``sag_m``) through exact points of the root land, fillet,
involute and tip land. Meshes need the same curve at their own spacing: the new
points are linearly interpolated in arc length on the fine polyline, so they stay
within its chord sag of the true curve, and the region junctions (root/fillet and
fillet/involute tangency points, the tip corner) are kept as points, so no new
segment cuts a corner.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .polyline import with_midpoints
from .profile import FILLET, INVOLUTE, ROOT_LAND, TIP_LAND, ToothProfile

__all__ = ["FINE_SAG_M", "region_junctions", "profile_at", "resample_profile"]

#: Chord sag (m) of the profile polylines that meshes are resampled from: 1 nm keeps
#: the resampled points (P2 mid-side points included) within 1 nm of the true curve,
#: far below the chord sag of a mesh edge (0.3-10 um at 0.2-0.4 mm edges).
FINE_SAG_M = 1e-9

# tooth_profile stores each junction once: the root/fillet and involute/tip joints as
# the last point of the lower region, the fillet/involute joint as the first involute
# point (its roll angle is exact there); True = the junction is the upper region's
# first point.
_JUNCTION_IS_UPPER = {(ROOT_LAND, FILLET): False, (FILLET, INVOLUTE): True, (INVOLUTE, TIP_LAND): False}


def _pieces(profile: ToothProfile) -> tuple[np.ndarray, np.ndarray]:
    """(junction indices incl. both ends, region of each piece between two junctions)."""
    reg = profile.region
    idx, pieces = [0], [int(reg[0])]
    for i in np.flatnonzero(reg[1:] != reg[:-1]):
        key = (int(reg[i]), int(reg[i + 1]))
        if key not in _JUNCTION_IS_UPPER:
            raise ValueError(f"unexpected region sequence {key} in the profile")
        idx.append(int(i) + 1 if _JUNCTION_IS_UPPER[key] else int(i))
        pieces.append(key[1])
    idx.append(len(reg) - 1)
    return np.array(idx), np.array(pieces, dtype=np.int8)


def region_junctions(profile: ToothProfile) -> np.ndarray:
    """Indices of the profile's end points and region junctions, increasing."""
    return _pieces(profile)[0]


def profile_at(profile: ToothProfile, s_new: np.ndarray) -> ToothProfile:
    """The profile at arc positions ``s_new`` (within [0, s_end]).

    Points, normals (renormalised) and wear depth are linearly interpolated in s on the
    source polyline. A point between two junctions gets the region of that piece; a
    point at a junction keeps the source's label there (fillet/involute joint:
    INVOLUTE, the other joints: the lower region). Roll angles are recomputed from the
    radius on the involute."""
    s = profile.s
    sn = np.asarray(s_new, dtype=float)
    junc, piece_region = _pieces(profile)
    sj = s[junc]
    piece = np.clip(np.searchsorted(sj, sn, side="right") - 1, 0, len(piece_region) - 1)
    region = piece_region[piece]
    at = np.abs(sn[:, None] - sj[None, :]) <= 1e-12 * max(float(s[-1]), 1e-300)
    hit = at.any(axis=1)
    region[hit] = profile.region[junc[np.argmax(at[hit], axis=1)]]
    xy = np.column_stack([np.interp(sn, s, profile.xy[:, k]) for k in (0, 1)])
    nrm = np.column_stack([np.interp(sn, s, profile.normal[:, k]) for k in (0, 1)])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    rb = profile.gear.base_radius_m
    radius = np.hypot(xy[:, 0], xy[:, 1])
    roll = np.where(region == INVOLUTE, np.sqrt(np.maximum((radius / rb) ** 2 - 1.0, 0.0)), np.nan)
    depth = np.interp(sn, s, profile.depth) if profile.depth is not None else np.zeros(len(sn))
    return replace(profile, xy=xy, normal=nrm, s=sn, radius=radius, roll=roll, region=region, depth=depth)


def resample_profile(profile: ToothProfile, spacing_m: dict, midpoints: bool = False) -> ToothProfile:
    """The profile resampled region by region in equal arc steps of at most
    ``spacing_m[region]``, keeping the junctions and both ends (space centre, tooth
    axis). ``midpoints``: also the arc-length mid-point of every step, as a quadratic
    chain (vertex, mid-point, vertex, ...; ``geometry.polyline``)."""
    s = profile.s
    junc, piece_region = _pieces(profile)
    s_new = [s[:1]]
    for i0, i1, r in zip(junc[:-1], junc[1:], piece_region):
        n = max(1, int(math.ceil((s[i1] - s[i0]) / float(spacing_m[int(r)]) - 1e-9)))
        s_new.append(np.linspace(s[i0], s[i1], n + 1)[1:])
    sn = np.concatenate(s_new)
    return profile_at(profile, with_midpoints(sn) if midpoints else sn)
