"""Every layer raises its input errors through the contract of gearwear.core.validation.

``fail`` / ``fail_range`` / ``fail_text`` set ``key``, ``value``, ``unit`` and ``why`` on the
InputError, so that the app's ``renamed`` swaps a layer's own parameter name for the user's
key (and rescales the value, and a range, for a key in other units) without parsing the
message. A bare ``InputError("...")`` carries none of them: the AST scan below refuses it in
core/, geometry/, analytic/ and dynamics/, and keeps the remaining ``raise ValueError`` of
those layers to a reviewed list of internal invariants (a user-reachable input goes through
the contract instead)."""

import ast
import math
from pathlib import Path

import numpy as np
import pytest

from gearwear.core.validation import Field, InputError, fail, fail_text, renamed

ROOT = Path(__file__).resolve().parents[1]
LAYERS = ("core", "geometry", "analytic", "dynamics")
CONTRACT = {"fail", "fail_range", "fail_text"}

#: InputError subclasses built by hand, and why that is right
SUBCLASS_SITES = {
    ("geometry/profile.py", "UndercutError"): "built from fail() in undercut_error, whose fields it copies",
    ("dynamics/simulate.py", "SolverError"): "a solver failure (divergence, step budget), not an input: no key",
}

#: the raise ValueError left in the layers: internal invariants, not user inputs (file, message start)
INTERNAL_VALUE_ERRORS = {
    ("core/validation.py", "fail_text: the message must start"),  # a caller's bug, not an input
    ("geometry/sampling.py", "unexpected region sequence"),  # a profile the code itself built
    ("geometry/polyline.py", "stitch: no pieces"),  # polyline helpers fed by the mesher
    ("geometry/polyline.py", "stitch: piece"),
    ("geometry/polyline.py", "stitch: the pieces do not close"),
    ("geometry/polyline.py", "project_to_polyline: the polyline needs"),
    ("geometry/polyline.py", "a quadratic chain needs"),
    ("geometry/spec.py", "inverse involute of negative value"),  # callers pass computed involutes
    ("geometry/profile.py", "depth has shape"),  # depths computed on the profile itself
    ("analytic/energy.py", "breaks_m must be a strictly increasing"),  # breaks from the profile
    ("analytic/energy.py", "load heights must lie in"),  # the user's radii are checked first
    # called only for the static coupling (analysis checks the model first)
    ("dynamics/equations.py", "accelerations_from_force: the dynamic coupling"),
}


def _layer_files():
    for layer in LAYERS:
        for path in sorted((ROOT / layer).glob("*.py")):
            yield f"{layer}/{path.name}", ast.parse(path.read_text())


def _name(node):
    f = node.func if isinstance(node, ast.Call) else None
    if isinstance(f, ast.Name):
        return f.id
    if isinstance(f, ast.Attribute):
        return f.attr
    return None


def _input_error_classes():
    names = {"InputError"}
    for _, tree in _layer_files():
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef) and any(isinstance(b, ast.Name) and b.id in names for b in node.bases):
                names.add(node.name)
    return names


def _message_start(node):
    """The literal start of a message expression (str or f-string), or None."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr) and node.values:
        first = node.values[0]
        if isinstance(first, ast.Constant):
            return first.value
        if isinstance(first, ast.FormattedValue) and isinstance(first.value, ast.Name):
            return "{" + first.value.id + "}"
    return None


def test_no_layer_builds_an_input_error_by_hand():
    classes = _input_error_classes()
    bad, seen = [], set()
    for rel, tree in _layer_files():
        for node in ast.walk(tree):
            name = _name(node) if isinstance(node, ast.Call) else None
            if name not in classes:
                continue
            if rel == "core/validation.py" and name == "InputError":
                continue  # the contract itself
            if (rel, name) in SUBCLASS_SITES:
                seen.add((rel, name))
                continue
            bad.append(f"{rel}:{node.lineno}: {name}(...) without fail/fail_range/fail_text")
    assert not bad, "\n".join(bad)
    assert seen == set(SUBCLASS_SITES), set(SUBCLASS_SITES) - seen


def test_every_fail_text_message_starts_with_its_key():
    bad, n = [], 0
    for rel, tree in _layer_files():
        for node in ast.walk(tree):
            if not (isinstance(node, ast.Call) and _name(node) == "fail_text") or rel == "core/validation.py":
                continue
            n += 1
            key, text = node.args[0], node.args[1]
            start = _message_start(text)
            if isinstance(key, ast.Constant) and key.value is None:
                continue
            want = (
                key.value
                if isinstance(key, ast.Constant)
                else "{" + key.id + "}"
                if isinstance(key, ast.Name)
                else None
            )
            if want is None or start is None or not start.startswith(want):
                bad.append(f"{rel}:{node.lineno}: key {ast.unparse(key)} vs message {ast.unparse(text)[:60]}")
    assert n > 40
    assert not bad, "\n".join(bad)


def test_raise_value_error_only_for_internal_invariants():
    found = set()
    for rel, tree in _layer_files():
        for node in ast.walk(tree):
            if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call) and _name(node.exc) == "ValueError":
                start = _message_start(node.exc.args[0]) if node.exc.args else ""
                known = [k for k in INTERNAL_VALUE_ERRORS if k[0] == rel and start and start.startswith(k[1])]
                found.add(known[0] if known else (rel, f"{start!r} (line {node.lineno})"))
    new = found - INTERNAL_VALUE_ERRORS
    assert not new, (
        f"raise ValueError in a layer: a user-reachable input goes through fail/fail_text, an "
        f"internal invariant goes into INTERNAL_VALUE_ERRORS with its reason: {sorted(new)}"
    )
    assert found == INTERNAL_VALUE_ERRORS, INTERNAL_VALUE_ERRORS - found


# ---- at run time: the fields are set, and renamed() uses them ----


@pytest.fixture(scope="module")
def model():
    from gearwear.dynamics import paper_pair

    return paper_pair()


def _raised(f):
    with pytest.raises(InputError) as info:
        f()
    return info.value


def test_dynamics_errors_carry_their_own_key(model):
    from gearwear.dynamics import indicators, simulate
    from gearwear.dynamics.simulate import round_to_table_periods
    from gearwear.dynamics.steady import steady_state

    x = np.sin(np.linspace(0, 64 * np.pi, 1280, endpoint=False))
    cases = [
        (lambda: model.with_(m_p=-1.0), "m_p", -1.0, ""),
        (lambda: model.with_(c_h=-2.5), "c_h", -2.5, "N s/m"),
        (lambda: model.with_(k_table=-np.ones(model.phi_table.size)), "k_table", None, "N/m"),
        (lambda: model.with_(centre_distance="both"), "centre_distance", "'both'", ""),
        (lambda: simulate(model, -1.0), "duration_s", -1.0, "s"),
        (lambda: simulate(model, 0.1, method="euler"), "method", "'euler'", ""),
        (lambda: simulate(model, 0.1, y0=[0.0]), "y0", None, ""),
        (lambda: simulate(model, 0.1, max_output_bytes=1000), "duration_s", 0.1, "s"),
        (lambda: round_to_table_periods(model, 0.1, 0.0, 0), "min_table_periods", 0, ""),
        (lambda: indicators.gear_indicators(x, 12800.0, 640.0, 20.0, K=0), "K", 0, ""),
        (lambda: indicators.gear_indicators(x, 12800.0, 640.0, 20.0, n_harmonics=99), "n_harmonics", 99, ""),
        (lambda: steady_state(model, tol=2.0), "tol", 2.0, ""),
    ]
    for f, key, value, unit in cases:
        err = _raised(f)
        assert (err.key, err.value, err.unit) == (key, value, unit), str(err)
        assert str(err).startswith(key) and err.why and str(err).endswith(err.why), str(err)


def test_a_renamed_dynamics_error_names_the_users_key_in_the_users_unit(model):
    err = _raised(lambda: model.with_(backlash_half_m=-1e-6))
    assert str(err) == "backlash_half_m = -1e-06 m: must be >= 0 (or None: effect absent)"
    out = renamed(err, {"backlash_half_m": ("effects.backlash.initial_um", 2e6, "um")})
    assert str(out) == "effects.backlash.initial_um = -2 um: must be >= 0 (or None: effect absent)"
    assert (out.key, out.value, out.unit) == ("effects.backlash.initial_um", -2.0, "um")


def test_a_renamed_dynamics_range_error_rescales_its_range(model):
    err = _raised(lambda: model.with_(alpha=2.0))
    assert str(err) == "alpha = 2.0 rad: must be in (0, pi/2)"  # the layer's own words
    out = renamed(err, {"alpha": ("pair.pressure_angle_deg", 180 / math.pi, "deg")})
    assert str(out) == "pair.pressure_angle_deg = 114.592 deg: must be in (0, 90) deg"
    assert out.field == Field("deg", 0.0, 90.0, lo_open=True, hi_open=True)


#: the app's renames of the solver's own names (as gearwear's simulate job has them)
SOLVER_KEYS = {"rtol": "solver.rtol", "discard_s": "solver.discard_s", "k_table": "effects.mesh_stiffness"}


def test_a_dynamics_error_renamed_to_a_scene_key_keeps_its_text(model):
    from gearwear.dynamics import simulate

    err = _raised(lambda: simulate(model, 0.1, rtol=1.5))
    assert err.key == "rtol" and err.field is not None
    assert str(renamed(err, SOLVER_KEYS)) == "solver.rtol = 1.5: must be in (0, 1)"
    err = _raised(lambda: simulate(model, 0.1, discard_s=0.2))
    assert str(renamed(err, SOLVER_KEYS)) == "solver.discard_s = 0.2 s: must be in [0, duration_s)"
    err = _raised(lambda: model.with_(k_table=-np.ones(model.phi_table.size)))
    assert str(renamed(err, SOLVER_KEYS)) == "effects.mesh_stiffness N/m: must be finite and >= 0"


def test_fail_text_sets_the_fields_and_refuses_a_key_the_message_does_not_start_with():
    err = fail_text("k_table", "k_table N/m: must be finite and >= 0", unit="N/m")
    assert (err.key, err.value, err.unit, err.why) == ("k_table", None, "N/m", "must be finite and >= 0")
    err = fail_text("worn_flank", "worn_flank must be 'right' or 'left'", "'top'")
    assert err.why == "must be 'right' or 'left'"
    err = fail_text(None, "WearSpec: exactly one of phase, max_depth_m, hours must be set")
    assert err.key is None and renamed(err, {"phase": "effects.wear.phase"}) is err
    with pytest.raises(ValueError, match="must start with its key"):
        fail_text("rtol", "tol = 2: must be in (0, 1)")
    # the same fields as fail() for a message fail() prints
    a, b = fail("K", 3, "", "too many"), fail_text("K", "K = 3: too many", 3)
    assert (str(a), a.key, a.value, a.unit, a.why) == (str(b), b.key, b.value, b.unit, b.why)
