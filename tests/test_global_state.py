"""Library code leaves process-wide state alone: the matplotlib backend, pyplot, the umask."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from gearwear.core.atomic import atomic_write, atomic_write_bytes


def _run(code: str) -> dict:
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def _umask_from_proc() -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("Umask:"):
            return int(line.split()[1], 8)
    raise LookupError("no Umask line")


# -- matplotlib ------------------------------------------------------------------------


def test_plotting_keeps_the_backend_and_never_imports_pyplot(tmp_path):
    """A notebook user's backend ("svg" here, set before any gearwear import) survives
    drawing and saving figures from the fem layer and from the app layer, and pyplot
    (which registers figures globally and may pick a GUI backend) stays unimported."""
    out = _run(f"""
        import json, sys
        from pathlib import Path
        import matplotlib
        matplotlib.use("svg")
        out = Path({str(tmp_path)!r})
        from gearwear.fem.convergence import plot_convergence
        rows = [dict(order=o, dofs=d, wall_s=w, error_pct_max=e, is_default=(o == 2 and d == 4000))
                for o, d, w, e in ((1, 1000, 0.1, 4.0), (1, 4000, 0.3, 1.0),
                                   (2, 1000, 0.2, 0.4), (2, 4000, 0.6, 0.05))]
        p1 = plot_convergence(rows, out / "conv.png")
        from gearwear import io
        from gearwear.jobs.sweep import Axis, figures
        axes = [Axis("operating.torque_Nm", (10.0, 20.0))]
        results = [{{"point": {{"operating.torque_Nm": t}}, "harmonics": {{"F_m": list(range(1, 11))}}}}
                   for t in (10.0, 20.0)]
        paths = [str(io.write_figure(f, out / n)) for n, f in figures(axes, results).items()]
        print(json.dumps({{"pyplot": "matplotlib.pyplot" in sys.modules,
                          "backend": matplotlib.get_backend(),
                          "files": [str(p1)] + paths}}))
    """)
    assert out["pyplot"] is False
    assert out["backend"] == "svg"
    for f in out["files"]:
        assert Path(f).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["conv.png", "harmonics_F_m.png"]


# -- atomic writes ------------------------------------------------------------------------


def test_atomic_write_gives_the_umask_mode_without_touching_the_umask(tmp_path):
    """Mode = 0o666 & ~umask, as for open(path, "w"); the library never calls os.umask
    (which would change the umask of every thread while it learns it)."""
    out = _run(f"""
        import json, os
        os.umask(0o027)
        def forbidden(*a):
            raise AssertionError("os.umask called")
        os.umask = forbidden
        from gearwear.core.atomic import atomic_write_bytes
        p = atomic_write_bytes({str(tmp_path / "a.txt")!r}, b"x")
        print(json.dumps({{"mode": os.stat(p).st_mode & 0o777}}))
    """)
    assert out["mode"] == 0o666 & ~0o027 == 0o640


def test_atomic_write_mode_follows_the_current_umask(tmp_path):
    if not Path("/proc/self/status").exists():
        pytest.skip("needs /proc/self/status to read the umask")
    umask = _umask_from_proc()
    p = atomic_write_bytes(tmp_path / "b.bin", b"\x00\x01")
    assert stat.S_IMODE(os.stat(p).st_mode) == 0o666 & ~umask
    assert p.read_bytes() == b"\x00\x01"


def test_atomic_write_temp_file_is_next_to_the_target_with_its_extension(tmp_path):
    seen = []

    def writer(tmp):
        seen.append(Path(tmp))
        Path(tmp).write_text("new")

    target = tmp_path / "sub" / "table.csv"
    atomic_write(target, writer)
    assert seen[0].parent == target.parent and seen[0].suffix == ".csv" and seen[0] != target
    assert target.read_text() == "new"
    assert [p.name for p in target.parent.iterdir()] == ["table.csv"]


def test_failed_writer_leaves_nothing_behind_and_keeps_the_old_file(tmp_path):
    target = tmp_path / "result.json"
    target.write_text("old")

    def writer(tmp):
        Path(tmp).write_text("half")
        raise RuntimeError("writer failed")

    with pytest.raises(RuntimeError, match="writer failed"):
        atomic_write(target, writer)
    assert [p.name for p in tmp_path.iterdir()] == ["result.json"]
    assert target.read_text() == "old"


# -- per-model derived constants ----------------------------------------------------------


def test_derived_constants_live_and_die_with_their_model():
    """derived() is computed once per model, a changed copy gets its own, and nothing
    module-level keeps a model (and its tables) alive once the caller drops it."""
    import gc
    import weakref

    import numpy as np

    from gearwear.dynamics.model import derived, rhs_python, static_equilibrium
    from gearwear.dynamics.presets import paper_pair

    m = paper_pair()
    d = derived(m)
    assert derived(m) is d
    f = rhs_python(0.0, static_equilibrium(m), m)
    faster = m.with_(omega_p=2 * m.omega_p)
    assert derived(faster)[0][13] == 2 * d[0][13] == 2 * m.omega_p  # P_OM: its own constants
    assert np.all(np.isfinite(f))
    ref = weakref.ref(m)
    del m, d, faster
    gc.collect()
    assert ref() is None


# -- damping ratios -------------------------------------------------------------------------


def test_damping_from_ratios_gives_the_damping_ratio_of_a_one_dof_oscillator():
    """m x'' + c x' + k x = 0 has roots -zeta w_n +- i w_n sqrt(1 - zeta^2): the real
    part over the modulus is -zeta."""
    import numpy as np

    from gearwear.dynamics.model import damping_from_ratios

    k, me, kb, mp, mg = 4.0e8, 1.3, 2.6e8, 3.75, 7.5
    c_h, (c_bp, c_bg) = damping_from_ratios(0.05, 0.02, k, me, kb, mp, mg)
    for c, kk, m, zeta in ((c_h, k, me, 0.05), (c_bp, kb, mp, 0.02), (c_bg, kb, mg, 0.02)):
        lam = np.roots([m, c, kk])
        assert -lam[0].real / abs(lam[0]) == pytest.approx(zeta, rel=1e-12)


def test_paper_pair_damping_uses_the_model_mean_stiffness_and_reduced_mass():
    import math

    from gearwear.dynamics.presets import paper_pair

    m = paper_pair(zeta_m=0.07, zeta_b=0.03)
    assert m.c_h == pytest.approx(2 * 0.07 * math.sqrt(m.k_mean * m.m_e), rel=1e-12)
    assert m.c_b[0] == pytest.approx(2 * 0.03 * math.sqrt(m.k_b * m.m_p), rel=1e-15)
    assert m.c_b[1] == pytest.approx(2 * 0.03 * math.sqrt(m.k_b * m.m_g), rel=1e-15)
