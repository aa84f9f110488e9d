"""report paper computes nothing twice: its tables are the cache entries its simulations
read, and its figures drawn on worker processes are the bytes of the serial ones."""

import sys
from pathlib import Path

import pytest

from gearwear.reports import paper
from gearwear.reports.paper_study import CLEARANCES_UM, PHASES


class _Asked(Exception):
    pass


def _simulation_clearance(scene, monkeypatch) -> float:
    """The clearance (m) under which the simulation of ``scene`` asks for its calibrated
    table: recorded at gearwear.stiffness.calibration.calibrated_table, then stopped."""
    from gearwear.jobs.simulate import stiffness_input
    from gearwear.stiffness import calibration

    asked = []

    def record(pair, wear, clearance_m=0.0, *args, **kwargs):
        asked.append(clearance_m)
        raise _Asked

    monkeypatch.setattr(calibration, "calibrated_table", record)
    with pytest.raises(_Asked):
        stiffness_input(scene)
    return asked[0]


@pytest.mark.parametrize(
    "base,sets",
    [(f"paper-wear-{p}", []) for p in PHASES]
    + [("paper-clearance", [f"effects.bearing_clearance.clearance_um={c}"]) for c in CLEARANCES_UM],
)
def test_the_report_asks_for_each_table_under_the_simulation_key(base, sets, monkeypatch):
    """Bit for bit the same float: 10 * 1e-6 and 10e-6 differ in the last bit, and the
    cache key of a table holds the clearance as given."""
    scene = paper._scene(base, ['effects.mesh_stiffness={source = "calibrated"}', *sets])
    assert paper.table_clearance_m(scene) == _simulation_clearance(scene, monkeypatch)


@pytest.mark.skipif(sys.platform != "linux", reason="forked workers (the default start method on Linux)")
def test_figures_drawn_on_workers_are_the_serial_bytes(tmp_path):
    sys.path.insert(0, str(Path(__file__).parent))
    from test_figures import paper_report_results

    from gearwear.reports.paper_render import render

    res = paper_report_results()
    names = [n for n in paper.figure_builders(res) if "harmonics" in n][:3] + ["fig15_geometry_clearance.png"]
    serial = render(res, names, tmp_path / "serial", dpi=60, workers=1)
    pooled = render(res, names, tmp_path / "pooled", dpi=60, workers=2)
    assert [p.name for p in pooled] == names
    assert [p.read_bytes() for p in serial] == [p.read_bytes() for p in pooled]
