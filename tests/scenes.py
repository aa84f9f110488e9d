"""Scene documents for tests: the paper pair as a complete document to start from.

A scene must name its pair and operating point (no pair is a default for another), so a
test that changes a few keys starts from the built-in ``paper-default`` document."""

from __future__ import annotations

import copy
from typing import Any

from gearwear.scene.files import builtin_scene_dict


def paper_doc(name: str = "paper-default") -> dict[str, Any]:
    """A fresh copy of a built-in scene's raw document."""
    return copy.deepcopy(builtin_scene_dict(name))


def with_paper(doc: dict[str, Any], base: str = "paper-default") -> dict[str, Any]:
    """``doc`` over the paper scene (tables merge key by key, other values replace)."""

    def merge(a: dict, b: dict) -> dict:
        out = dict(a)
        for k, v in b.items():
            out[k] = merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
        return out

    return merge(paper_doc(base), doc)


def paper_pair_from(doc: dict[str, Any]):
    """``gearwear.scene.model.pair_from_dict`` of ``doc`` over the paper scene: the keys a test
    changes, the paper pair's values for the rest."""
    from gearwear.scene.model import pair_from_dict

    return pair_from_dict(with_paper(doc))


def published_text() -> str:
    """What the project publishes, whitespace-normalised: README.md and every docs/*.md
    (the numbers moved from the README to the documents it links)."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    files = [root / "README.md"] + sorted((root / "docs").glob("*.md"))
    return " ".join(" ".join(f.read_text().split()) for f in files)
