"""The pair FE refuses a body too large for this machine before it meshes it (fem.memory).

The bug's class: an input the tool accepts and then spends half an hour and all the memory on
(the 100/500 solid-blank atlas corner: 33 min, 16 GB, no result). Checked against truths
that do not come from the estimate: the element and dof counts of the real Gmsh meshes of
unequal, shifted and driver-larger pairs; the CLI's contract (one line naming the key, exit
2, nothing written) with Gmsh never called; the budget variable's bad values. The fitted
constants are pinned to the committed fit (a labelled regression check).
"""

from __future__ import annotations

import json
import math
from collections import OrderedDict
from pathlib import Path

import pytest

import gearwear.fem.pair_body as pb
import gearwear.fem.pair_model as pmod
from gearwear.cli.app import main
from gearwear.core.validation import InputError
from gearwear.fem import memory
from gearwear.fem.pair import pair_contact
from gearwear.geometry.spec import PairSpec
from tests.pairs import DRIVER_LARGER, UNEQUAL

ROOT = Path(__file__).resolve().parents[1]
SOLID_100_500 = """
name = "solid-100-500"
extends = "paper-default"
[pair]
teeth = [100, 500]
module_mm = 3.0
face_width_mm = 30.0
hub_radius_mm = [29.85, 149.25]
"""


class _Meshed(Exception):
    pass


def _real_bodies(pair: PairSpec, monkeypatch) -> list[tuple[float, int]]:
    """(estimated dofs, dofs of the real mesh) of both bodies of ``pair``: the pair FE run up
    to its condensation (not run)."""
    estimates, real = {}, {}
    check = pmod.check_bodies

    def spy_check(bodies):
        for _, _, _, bore, dofs in bodies:
            estimates[round(bore, 12)] = dofs
        check(bodies)

    def stop(cls, gear, sizes, r_lo, gm, model, *a, **k):
        real[round(gear.hub_radius_m, 12)] = int(model.basis.N)
        if len(real) == 2:
            raise _Meshed

    monkeypatch.setattr(pmod, "check_bodies", spy_check)
    monkeypatch.setattr(pb, "_condensed", stop)
    with pytest.raises(_Meshed):
        pair_contact(pair, torque_Nm=100.0, positions=4)
    return [(estimates[k], real[k]) for k in sorted(real)]


@pytest.mark.parametrize("pair", [UNEQUAL, DRIVER_LARGER], ids=["unequal_23_47", "driver_larger_47_23"])
def test_the_estimate_is_the_real_meshes_dofs_within_15_percent(pair, monkeypatch):
    monkeypatch.setattr(pmod, "_BODY_CACHE", OrderedDict())  # build, and leave no half-built body behind
    for est, real in _real_bodies(pair, monkeypatch):
        assert abs(est / real - 1) < 0.15, (est, real)


def test_a_body_too_large_is_refused_in_one_line_before_gmsh(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(memory.ENV, "20")
    monkeypatch.setattr(pb, "mesh_full_gear", lambda *a, **k: pytest.fail("Gmsh ran"))
    scene = tmp_path / "solid.toml"
    scene.write_text(SOLID_100_500)
    out = tmp_path / "out"
    code = main(["stiffness", str(scene), "--method", "fem", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert err[0].startswith("gearwear: error: pair.hub_radius_mm[1] = 149.25 mm: the pair FE's body of the gear")
    assert "more than the 20 GB it may use (GEARWEAR_FE_MEMORY_GB)" in err[0]
    assert not out.exists()


def test_the_budget_variable(monkeypatch):
    monkeypatch.setenv(memory.ENV, "0.05")  # 50 MB: less than any body
    with pytest.raises(InputError, match=r"^hub_radius_m\[0\] = .* more than the 0.05 GB it may use"):
        memory.check_bodies([(0, "pinion", 23, UNEQUAL.hub_radius_m[0], 6e4)])
    for bad in ("abc", "-1", "0", "nan", "inf"):
        monkeypatch.setenv(memory.ENV, bad)
        with pytest.raises(InputError, match=rf"^GEARWEAR_FE_MEMORY_GB = '{bad}': must be a number of GB > 0"):
            memory.budget_bytes()
    monkeypatch.delenv(memory.ENV)
    assert memory.budget_bytes() == pytest.approx(0.8 * _physical_bytes())


def _physical_bytes() -> float:
    with open("/proc/meminfo") as f:  # an independent reading of the same quantity
        kb = next(int(line.split()[1]) for line in f if line.startswith("MemTotal:"))
    return kb * 1024.0


def test_more_blank_more_dofs_and_memory():
    """A smaller bore adds blank area at the interior size, a finer contact zone adds its graded
    band; the peak grows with n log n."""
    areas = [memory.body_dofs(0.02, 0.07, b, 1.2e-3, 0.9e-3, 0.01, 3e-5) for b in (0.06, 0.04, 0.02, 0.005)]
    assert all(a < b for a, b in zip(areas, areas[1:]))
    # the blank's share by hand: pi (r_f^2 - r_b^2) / (sqrt(3)/4 h^2) elements, 4.2 dofs each
    d = memory.body_dofs(0.02, 0.07, 0.02, 1.2e-3, 0.9e-3) - memory.body_dofs(0.02, 0.07, 0.06, 1.2e-3, 0.9e-3)
    assert d == pytest.approx(4.2 * math.pi * (0.06**2 - 0.02**2) / (math.sqrt(3) / 4 * 1.2e-3**2), rel=1e-12)
    # the graded band by hand: int_0^inf L / (a (h_c + g d)^2) dd = L / (a g h_c), times C_CONTACT
    band = memory.body_dofs(0.02, 0.07, 0.06, 1.2e-3, 0.9e-3, 0.01, 2e-5) - memory.body_dofs(
        0.02, 0.07, 0.06, 1.2e-3, 0.9e-3, 0.0, 2e-5
    )
    assert band == pytest.approx(4.2 * memory.C_CONTACT * 0.01 / (math.sqrt(3) / 4 * 0.25 * 2e-5), rel=1e-12)
    n = [1e4, 1e5, 1e6]
    assert [memory.peak_bytes(x) for x in n] == sorted(memory.peak_bytes(x) for x in n)


def test_regression_the_constants_are_the_committed_fit():
    """Labelled regression: fem.memory's constants are benchmarks/bench_fem_memory.py's fits
    (benchmarks/results/bench_fem_memory.json), rounded."""
    fit = json.loads((ROOT / "benchmarks/results/bench_fem_memory.json").read_text())
    assert fit["elements_fit"]["body"] == pytest.approx(1.0, rel=0.05)
    assert fit["elements_fit"]["teeth"] == pytest.approx(memory.C_TEETH, rel=0.05)
    assert fit["elements_fit"]["contact"] == pytest.approx(memory.C_CONTACT, rel=0.05)
    assert fit["elements_fit"]["tooth0"] == pytest.approx(memory.N_TOOTH0, rel=0.1)
    lo, hi = fit["dofs_per_element"]
    assert lo <= memory.DOFS_PER_ELEMENT <= hi * 1.01
    assert fit["memory_fit"]["M0_MiB"] * 2**20 == pytest.approx(memory.M0_BYTES, rel=0.1)
    assert fit["memory_fit"]["c_bytes"] == pytest.approx(memory.C_FILL_BYTES, rel=0.05)
    assert fit["estimate_max_rel_error"] < 0.1 and fit["memory_model_max_rel_error"] < 0.15
    # the model is the committed code's: every peak's model_MB is fem.memory.peak_bytes of its bodies
    for p in fit["peaks"]:
        assert p["model_MB"] == pytest.approx(memory.peak_bytes(p["dofs"]) / 2**20, rel=1e-9)


def _checked(pair: PairSpec, monkeypatch) -> list[tuple]:
    """The bodies pair_model hands to the memory check (stopped there: nothing is meshed)."""
    seen: list[tuple] = []

    def spy(bodies):
        seen.extend(bodies)
        raise _Meshed

    monkeypatch.setattr(pmod, "check_bodies", spy)
    with pytest.raises(_Meshed):
        pmod.pair_model(pair, None, 40.0)
    return seen


@pytest.mark.parametrize("pair", [UNEQUAL, DRIVER_LARGER], ids=["unequal_23_47", "driver_larger_47_23"])
def test_bodies_built_together_are_checked_together(pair, monkeypatch):
    """The bug's class: a check per body passed two bodies that each fit but are built at the
    same time (fem.pair_model overlaps them), so their factors can be resident together: the
    40/80 high-contact-ratio corner peaked at 929 MB against 785 MB for its larger body
    alone. Both bodies of an unequal pair are checked at once, and the budget they need is
    M0 plus both fills: a budget between one body's need and the pair's is refused, naming
    the larger body."""
    bodies = _checked(pair, monkeypatch)
    assert sorted(b[0] for b in bodies) == [0, 1]
    monkeypatch.undo()
    n = [b[4] for b in bodies]
    fill = [memory.C_FILL_BYTES * x * math.log2(x) for x in n]
    assert memory.peak_bytes(n) == pytest.approx(memory.M0_BYTES + sum(fill), rel=1e-12)
    # a budget above the larger body's need alone, below the pair's
    between = memory.M0_BYTES + max(fill) + 0.5 * min(fill)
    monkeypatch.setenv(memory.ENV, repr(between / 1e9))
    memory.check_bodies([max(bodies, key=lambda b: b[4])])  # the old per-body check passed
    big = max(range(2), key=lambda i: n[i])
    with pytest.raises(InputError, match=rf"^hub_radius_m\[{bodies[big][0]}\] = .*built at the same time"):
        memory.check_bodies(bodies)


def test_two_equal_gears_check_one_body(monkeypatch):
    """Equal gears share one body (fem.pair_model's cache key): it is counted once."""
    from gearwear.geometry.spec import default_pair

    bodies = _checked(default_pair(), monkeypatch)
    assert [b[0] for b in bodies] == [0]
