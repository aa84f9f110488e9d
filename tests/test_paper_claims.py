"""The paper's trend claims as data (gearwear/data/claims/paper.toml): every claim names
a quantity, mechanism, context or row that gearwear.reports.paper knows, a direction that
classify()/agrees() understand, and trends() gives exactly one row per claim, in order."""

import json
import string
import tomllib
from importlib import resources
from pathlib import Path

import pytest

from gearwear.reports import paper, paper_trends
from gearwear.reports.paper_study import SIGNALS
from gearwear.reports.paper_trends import (
    CONTEXTS,
    DIRECTIONS,
    MECHANISM_PARAMS,
    MECHANISMS,
    QUANTITIES,
    ROWS,
    agrees,
    classify,
    load_claims,
)

ROOT = Path(__file__).resolve().parents[1]
FIELDS = {
    "where",
    "paper",
    "claim",
    "quantity",
    "signal",
    "k",
    "harmonics",
    "note",
    "mechanisms",
    "context",
    "context_from",
    "row",
    "phase",
    "study",
}
UNITS = {name: unit for name, unit, _, _ in SIGNALS}
CLAIMS = load_claims()


def _entries() -> list[dict]:
    text = resources.files("gearwear.data.claims").joinpath("paper.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)["claim"]


def test_the_data_file_loads_with_known_fields():
    entries = _entries()
    assert entries and all(isinstance(e, dict) for e in entries)
    for e in entries:
        assert set(e) <= FIELDS, (set(e) - FIELDS, e)
        assert e["where"] and e["paper"]
        assert ("claim" in e) != ("harmonics" in e), e  # a single claim or a family
        assert ("quantity" in e) != ("row" in e), e  # checked against a quantity or a row of its own
    assert len(CLAIMS) >= len(entries)


def test_the_claims_file_is_not_a_scene():
    from gearwear.scene.files import builtin_scene_names

    assert all("claim" not in name and name != "paper" for name in builtin_scene_names())


def test_every_claim_names_known_things():
    for c in CLAIMS:
        if "row" in c:
            assert c["row"] in ROWS, c
            assert c["claim"] == ROWS[c["row"]][0], c  # the claim that row evaluates
            assert not {"quantity", "mechanisms", "context_from", "note"} & set(c), c
            continue
        assert c["quantity"] in QUANTITIES, c
        for key in c.get("mechanisms", ()):
            assert key in MECHANISMS, c
        if "context_from" in c:
            assert c["context_from"] in CONTEXTS, c
        if "signal" in c:
            assert c["signal"] in UNITS, c
            assert UNITS[c["signal"]] in c["note"], c  # the note's unit is the one the values are in
        if "k" in c:
            assert isinstance(c["k"], int) and 1 <= c["k"] <= (4 if c["quantity"].endswith("_wear") else 10), c


def test_every_mechanism_gets_the_numbers_its_text_quotes():
    for key, (direction, text) in MECHANISMS.items():
        fields = {f for _, f, _, _ in string.Formatter().parse(text) if f}
        assert bool(fields) == (key in MECHANISM_PARAMS), key
    assert set(MECHANISM_PARAMS) <= set(MECHANISMS)


def test_every_direction_is_one_classify_and_agrees_understand():
    for c in CLAIMS:
        if "row" in c:
            continue
        assert c["claim"] in DIRECTIONS, c
        assert agrees(c["claim"], c["claim"]) == "agree", c
    # DIRECTIONS are exactly the words of classify()
    shapes = ([0, 1, 2], [2, 1, 0], [2, 0, 1], [0, 2, 1], [0, 2, 1, 3], [1, 1, 1])
    assert sorted({classify(y) for y in shapes}) == sorted(DIRECTIONS)


def test_no_claim_twice():
    pairs = [(c["where"], c["paper"]) for c in CLAIMS]
    assert len(pairs) == len(set(pairs)), sorted(p for p in pairs if pairs.count(p) > 1)


def test_harmonic_families_expand_in_order():
    fam = next(e for e in _entries() if e.get("signal") == "F_m" and e.get("quantity") == "harmonic_vs_clearance")
    rows = [c for c in CLAIMS if c["where"] == fam["where"] and c.get("k")]
    assert [c["k"] for c in rows] == [int(k) for k in fam["harmonics"]]
    assert rows[0]["paper"] == "1 x fm of F_m decrease then increase with clearance"
    assert all("{" not in c["paper"] for c in CLAIMS)


def test_the_committed_report_has_the_claims_in_order():
    """reports/paper/trends.json (written with the code before the claims became data)."""
    rows = json.loads((ROOT / "reports" / "paper" / "trends.json").read_text())
    assert [(r["where"], r["paper"], r["claim"]) for r in rows] == [
        (c["where"], c["paper"], c["claim"]) for c in CLAIMS
    ]


@pytest.fixture(scope="module")
def res(tmp_path_factory):
    """compute() as tests/test_outputs.py::test_report_paper_twice_same_bytes runs it:
    analytic tables (no FE), 50 ms simulations."""
    from gearwear.analytic.tvms import mesh_stiffness
    from gearwear.stiffness import calibration as calibrate

    def table(pair, wear, clearance_m=0.0, torque_Nm=40.0, points=360, *args, **kwargs):
        return mesh_stiffness(
            pair, method="ishikawa", points=48, torque_Nm=torque_Nm, clearance_m=clearance_m, wear=wear
        )

    real_scene = paper._scene
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("GEARWEAR_CACHE", str(tmp_path_factory.mktemp("cache")))
        mp.setattr(calibrate, "run_fe", lambda *a, **k: None)
        mp.setattr(calibrate, "calibrated_table", table)
        mp.setattr(
            paper,
            "_scene",
            lambda base, sets: real_scene(
                base,
                [s for s in sets if "mesh_stiffness" not in s] + ["solver.duration_s=0.05", "solver.discard_s=0.02"],
            ),
        )
        yield paper.compute()


def test_one_row_per_claim(res):
    rows = paper.trends(res)
    assert len(rows) == len(CLAIMS) == 63
    assert [(r["where"], r["paper"], r["claim"]) for r in rows] == [
        (c["where"], c["paper"], c["claim"]) for c in CLAIMS
    ]
    assert all(list(r) == ["where", "paper", "claim", "ours", "verdict", "why"] for r in rows)


def test_mechanism_numbers_fill_their_texts(res):
    for key, params in MECHANISM_PARAMS.items():
        text = paper_trends._mech(key, **params(res))[1]
        assert "{" not in text and "nan" not in text, (key, text)
