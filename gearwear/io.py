"""Atomic, traceable output folders.

Every command that writes files (``--out FOLDER``) writes them into a fresh temporary
folder next to FOLDER and swaps it in as a whole (``gearwear.core.atomic.atomic_folder``):
the set of files is complete or absent, and a re-run replaces the previous set with no
stale leftovers. Each folder gets

* ``manifest.json``: the command, the software version, the provenance of the inputs
  (the fully resolved scene, its SHA-256, the SHA-256 of every file the scene refers
  to, the command's options) and the SHA-256 and size of every file in the folder.
  It also marks the folder as gearwear's: only an empty folder, a folder with a
  gearwear manifest that holds nothing but gearwear outputs, or (outputs committed
  before manifests existed) a folder holding only names the command writes may be
  replaced (:func:`check_out`, :func:`foreign_entry`); a user's file is never deleted.
* ``timing.json``: wall times of the run; the only file that differs between two runs
  with the same inputs. No result file holds a wall time.

Result CSVs (and the mesh ``.vtu``) also get a JSON sidecar (``<file>.json``) with the
inputs, their SHA-256 (inputs + software version), the method and the version.
"""

from __future__ import annotations

import fnmatch
import hashlib
import io
import json
import math
import os
import zipfile
from pathlib import Path
from typing import Any, Callable, Iterable

from gearwear import __version__
from gearwear.core.atomic import atomic_folder, atomic_write_bytes
from gearwear.core.validation import InputError

MANIFEST = "manifest.json"
TIMING = "timing.json"

#: The names each command writes at the top of its folder (fnmatch patterns; a trailing
#: "/" marks a sub-folder). A folder without a manifest is replaced only if it holds
#: nothing else: outputs committed before manifests existed.
OUTPUT_NAMES: dict[str, tuple[str, ...]] = {
    "geometry": (
        "profile.csv",
        "profile.csv.json",
        "tooth.png",
        "pinion_mesh.vtu",
        "pinion_mesh.vtu.json",
        "summary.json",
    ),
    "stiffness": (
        "stiffness_*.csv",
        "stiffness_*.csv.json",
        "stiffness.png",
        "mean_vs_clearance.png",
        "stiffness_summary.json",
        "fields_*/",
        "harris_map.png",
        "harris_map.csv",
    ),
    "verify": ("compliance.png", "convergence.png", "verification.md", "verification.json"),
    "calibrate": ("calibrated_*.csv", "calibrated_*.csv.json"),
    "simulate": ("signals.npz", "signals.csv", "signals.csv.json", "response.png", "spectrum.png", "summary.json"),
    "sweep": ("sweep.csv", "sweep.csv.json", "harmonics_*.png"),
    "atlas": ("atlas.csv", "atlas.csv.json"),
    "runup": ("runup.csv", "runup.csv.json", "runup_summary.json", "kv.png", "order_map_*.png", "campbell_*.png"),
    "report paper": ("README.md", "fig[0-9][0-9]_*.png", "trends.json"),
    "report pair": ("README.md", "report.json", "stiffness.png", "ste_load.png", "kv.png"),
    "diagnose": ("diagnosis.json", "features.csv", "features.csv.json", "corner.png", "features.png"),
    "diagnose plan": ("plan.json", "plan.csv", "plan.csv.json"),
}


# -- single files ------------------------------------------------------------------------


def write_bytes(path: str | Path, data: bytes) -> Path:
    return atomic_write_bytes(path, data)


def write_text(path: str | Path, text: str) -> Path:
    return write_bytes(path, text.encode("utf-8"))


def json_text(obj: Any, indent: int | None = 2) -> str:
    """Strict JSON (RFC 8259) with sorted keys: NaN and infinities become ``null``, since
    JSON has no such numbers and Python's ``NaN`` token breaks other readers; numpy
    arrays and scalars become lists and numbers."""
    return json.dumps(_strict(obj), indent=indent, sort_keys=True, allow_nan=False, default=_default)


def _strict(o: Any) -> Any:
    if isinstance(o, float):
        return o if math.isfinite(o) else None
    if isinstance(o, dict):
        return {k: _strict(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_strict(v) for v in o]
    if hasattr(o, "tolist"):
        return _strict(o.tolist())
    return o


def write_json(path: str | Path, obj: Any, indent: int | None = 2) -> Path:
    """Strict JSON (:func:`json_text`) and a final newline: the same object gives the same bytes."""
    return write_text(path, json_text(obj, indent) + "\n")


def write_figure(fig, path: str | Path, dpi: float | None = None) -> Path:
    """Save a matplotlib figure atomically (PNG, deterministic metadata) at ``dpi``, by
    default the figure's own (gearwear.plotting.FIGURE_DPI for its figures)."""
    return write_bytes(path, figure_bytes(fig, dpi))


def figure_bytes(fig, dpi: float | None = None) -> bytes:
    """The PNG bytes :func:`write_figure` writes (a figure rendered in another process, e.g. a
    sweep's worker, comes back as bytes); ``dpi`` None: the figure's own."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi or fig.dpi, metadata={"Software": None}, bbox_inches="tight")
    return buf.getvalue()


def npz_bytes(arrays: dict[str, Any]) -> bytes:
    """A compressed ``.npz`` (readable by ``numpy.load``) with fixed zip timestamps and
    permissions, so the same arrays give the same bytes (``np.savez`` stamps the clock)."""
    import numpy as np

    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for name, arr in arrays.items():
            info = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            member = io.BytesIO()
            np.lib.format.write_array(member, np.asanyarray(arr), allow_pickle=False)
            zf.writestr(info, member.getvalue())
    return buf.getvalue()


def canonical_json(obj: Any) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), default=_default)


def _default(o: Any):
    if hasattr(o, "tolist"):
        return o.tolist()
    if isinstance(o, (set, tuple)):
        return list(o)
    return str(o)


def input_hash(inputs: Any) -> str:
    """SHA-256 of the canonical JSON of ``inputs`` and the software version."""
    return hashlib.sha256((canonical_json(inputs) + __version__).encode()).hexdigest()


def file_sha256(path: str | Path) -> str:
    """SHA-256 of an input file: of the bytes it was parsed from when it was read through
    core.inputs.read_input (one read: what is hashed is what was used), else of the file."""
    from gearwear.core.inputs import recorded_sha256

    known = recorded_sha256(path)
    if known is not None:
        return known
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def sidecar(path: str | Path, inputs: Any, method: str, extra: dict | None = None) -> Path:
    """Write ``<path>.json`` describing how ``path`` was made. ``inputs`` is hashed;
    ``extra`` (e.g. the scene's name, a summary) is recorded but not hashed."""
    return write_bytes(str(path) + ".json", sidecar_bytes(path, inputs, method, extra))


def sidecar_bytes(path: str | Path, inputs: Any, method: str, extra: dict | None = None) -> bytes:
    """The bytes :func:`sidecar` writes."""
    meta = {
        "file": Path(path).name,
        "software": "gearwear",
        "version": __version__,
        "method": method,
        "inputs": inputs,
        "input_sha256": input_hash(inputs),
    }
    if extra:
        meta.update(extra)
    return (json_text(meta) + "\n").encode("utf-8")


# -- timing ------------------------------------------------------------------------------


def is_timing_key(key: str) -> bool:
    return key == "wall_s" or key.endswith("_wall_s") or key in ("compile_s", "build_s", "timings")


def without_timing(obj: Any) -> Any:
    """``obj`` (nested dicts and lists) without its wall-time keys (``wall_s``,
    ``*_wall_s``, ``compile_s``, ``build_s``, ``timings``): what goes into a result file."""
    if isinstance(obj, dict):
        return {k: without_timing(v) for k, v in obj.items() if not is_timing_key(str(k))}
    if isinstance(obj, (list, tuple)):
        return [without_timing(v) for v in obj]
    return obj


# -- provenance --------------------------------------------------------------------------


def scene_inputs(scene) -> dict[str, Any]:
    """What a scene contributes to the inputs of a result: the fully resolved scene
    (``gearwear.scene.checks.resolved_dict``: every default filled in) and its SHA-256.

    A file the scene refers to (``effects.mesh_stiffness.path``) enters by its content:
    the path is replaced by ``sha256:<hex>`` of the file, so editing the table changes
    the hash and moving it does not. The scene's ``name`` and ``description`` are left
    out: they label a run but change no number, so two files with the same content and
    different names hash the same (the name is recorded next to the hash, see
    :func:`scene_labels`)."""
    from gearwear.scene.checks import resolved_dict

    doc = resolved_dict(scene.doc)
    doc.pop("name", None)
    doc.pop("description", None)
    ms = doc.get("effects", {}).get("mesh_stiffness")
    if isinstance(ms, dict) and ms.get("path"):
        ms["path"] = f"sha256:{file_sha256(ms['path'])}"
    fl = doc.get("flank")
    if isinstance(fl, dict) and fl.get("deviation_csv"):
        fl["deviation_csv"] = [f"sha256:{file_sha256(p)}" if p else "" for p in fl["deviation_csv"]]
    return {"scene_sha256": hashlib.sha256(canonical_json(doc).encode()).hexdigest(), "scene": doc}


def referenced_files(scene) -> dict[str, str]:
    """Scene key -> path of every file the scene refers to (stiffness table, measured
    deviations)."""
    out: dict[str, str] = {}
    doc = scene.doc
    if doc is None:
        return out
    if doc.effects.mesh_stiffness is not None and doc.effects.mesh_stiffness.path:
        out["effects.mesh_stiffness.path"] = str(doc.effects.mesh_stiffness.path)
    if doc.flank is not None and doc.flank.deviation_csv:
        for i, p in enumerate(doc.flank.deviation_csv):
            if p:
                out[f"flank.deviation_csv[{i}]"] = str(p)
    return out


def scene_labels(scene) -> dict[str, Any]:
    """The scene's name and the paths of the files it refers to: recorded, not hashed."""
    out: dict[str, Any] = {"scene_name": scene.name}
    files = referenced_files(scene)
    if files:
        out["referenced_files"] = {key: {"path": p, "sha256": file_sha256(p)} for key, p in files.items()}
    return out


# -- output folders ----------------------------------------------------------------------


def check_out(out: str | None, command: str) -> Path | None:
    """The --out folder, checked before any work: a new folder, an empty one, or one
    gearwear wrote (it is replaced as a whole, :func:`foreign_entry`). Raises a
    one-line InputError otherwise."""
    if out is None:
        return None
    if not str(out).strip():
        raise InputError(f"--out = {out!r}: empty; give a folder name")
    p = Path(out)
    real = Path(os.path.realpath(p))
    cwd = Path(os.path.realpath(os.getcwd()))
    if real == cwd or real in cwd.parents:
        raise InputError(
            f"--out = {out}: is the current folder or contains it, and the output folder is replaced "
            "as a whole; give a sub-folder"
        )
    if p.exists() and not p.is_dir():
        raise InputError(f"--out = {out}: exists and is not a folder")
    parent = next((q for q in real.parents if q.exists()), Path("/"))
    if not parent.is_dir() or not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"--out = {out}: {parent} is not a writable folder")
    if p.is_dir():
        replaceable(out, command)(p)
    return p


def replaceable(out: str | Path, command: str, during: bool = False) -> Callable[[Path], None]:
    """The check that the folder given as ``--out = out`` may be replaced by the output of
    ``command`` (:func:`check_out` before any work; core.atomic.swap_in again at the swap,
    ``during=True``, on the folder as it is then): a one-line InputError if it holds an
    entry gearwear did not write (:func:`foreign_entry`), or a folder whose old content
    could not be deleted (read-only), so that no file of the user's is ever deleted and no
    hidden ``.NAME.*.old`` folder is left behind."""

    def check(folder: Path) -> None:
        bad = foreign_entry(folder, command)
        if bad is not None and during:
            raise InputError(
                f"--out = {out}: {bad} appeared in it during the run and gearwear did not write it, "
                "so the folder was not replaced (this run's results were not kept); move it away "
                "and run again"
            )
        if bad is not None and read_manifest(folder) is None:
            raise InputError(
                f"--out = {out}: exists, is not empty and was not written by gearwear "
                f"(no {MANIFEST} of gearwear's; it holds {bad}); give a new or empty folder"
            )
        if bad is not None:
            raise InputError(
                f"--out = {out}: holds {bad}, which gearwear did not write, and the folder is replaced "
                "as a whole; move it away or give a new or empty folder"
            )
        locked = read_only_entry(folder)
        if locked is not None:
            raise InputError(
                f"--out = {out}: {locked} is read-only, so its old content could not be deleted when "
                "the folder is replaced as a whole; make it writable or give a new folder"
            )

    return check


def read_only_entry(folder: Path) -> str | None:
    """The first folder in ``folder`` (itself included: ".") whose entries this process may
    not delete (no write or search permission), or None."""
    for root, dirs, _ in os.walk(folder):
        if not os.access(root, os.W_OK | os.X_OK):
            rel = Path(root).relative_to(folder).as_posix()
            return "." if rel == "." else rel + "/"
        dirs[:] = [d for d in dirs if not os.path.islink(os.path.join(root, d))]
    return None


#: the largest manifest read (a manifest lists a folder's files with their hashes)
MANIFEST_LIMIT_BYTES = 16 << 20


def read_manifest(folder: Path) -> dict[str, Any] | None:
    """The folder's ``manifest.json`` if it is gearwear's, else None: a regular file (read
    bounded, core.inputs), JSON naming gearwear as the software and one of its commands,
    with the SHA-256 and size of each file it lists. A file of the user's that happens to
    be called manifest.json is not gearwear's manifest."""
    from gearwear.core.inputs import read_bounded

    data, _ = read_bounded(folder / MANIFEST, "manifest", MANIFEST_LIMIT_BYTES)
    try:
        m = json.loads(data) if data is not None else None
    except ValueError:
        return None
    if not (isinstance(m, dict) and m.get("software") == "gearwear" and m.get("command") in OUTPUT_NAMES):
        return None
    files = m.get("files")
    if not isinstance(files, dict) or not all(
        isinstance(v, dict) and isinstance(v.get("sha256"), str) and isinstance(v.get("bytes"), int)
        for v in files.values()
    ):
        return None
    return m


def _output_name(name: str, commands, manifest: bool) -> bool:
    """``name`` is one ``commands`` write (``manifest``: the folder has gearwear's manifest;
    without one, a file called manifest.json is not gearwear's)."""
    own = (MANIFEST, TIMING) if manifest else (TIMING,)
    return any(fnmatch.fnmatchcase(name, pat) for c in commands for pat in OUTPUT_NAMES[c] + own)


def foreign_entry(folder: Path, command: str) -> str | None:
    """The first entry of ``folder`` that gearwear did not write, or None if the
    output of ``command`` may replace the folder as a whole.

    * A folder with a gearwear manifest: every entry is listed in it, or has the name
      of some command's output (a stale file of an earlier run), or is a sub-folder
      that is itself gearwear's (e.g. another command's --out inside it).
    * A folder without a manifest (outputs committed before manifests existed, e.g.
      reports/): every entry has a name ``command`` writes.
    * An empty folder.

    So a file of the user's (a scene, notes) is never deleted by a re-run."""
    m = read_manifest(folder)
    listed = {Path(f).parts[0] for f in (m or {}).get("files", {})}
    commands = list(OUTPUT_NAMES) if m is not None else [command]
    for e in sorted(folder.iterdir()):
        if e.is_symlink() or not (e.is_dir() or e.is_file()):
            return e.name
        if e.name in listed or _output_name(e.name + ("/" if e.is_dir() else ""), commands, m is not None):
            continue
        if m is not None and e.is_dir() and read_manifest(e) is not None and foreign_entry(e, command) is None:
            continue
        return e.name + ("/" if e.is_dir() else "")
    return None


def manifest(folder: Path, command: str, provenance: dict[str, Any]) -> dict[str, Any]:
    files = {}
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder).as_posix()
        if p.is_file() and rel not in (MANIFEST, TIMING):
            files[rel] = {"sha256": file_sha256(p), "bytes": p.stat().st_size}
    return {
        "software": "gearwear",
        "version": __version__,
        "command": command,
        "provenance": provenance,
        "files": files,
        "note": f"every file in this folder but {TIMING} (wall times) with its SHA-256; the folder is "
        "replaced as a whole when gearwear writes into it again",
    }


def write_folder(
    out: Path,
    command: str,
    provenance: dict[str, Any],
    writer: Callable[[Path], Iterable[Path]],
    timing: dict[str, Any] | None = None,
) -> list[Path]:
    """Run ``writer(folder)`` in a fresh temporary folder, add ``timing.json`` and
    ``manifest.json``, and swap the folder in at ``out`` as a whole. Returns the written
    files at their final place. On any error or Ctrl-C nothing at ``out`` changes."""
    with atomic_folder(out, replaceable(out, command, during=True)) as tmp:
        written = list(writer(tmp))
        written.append(write_json(tmp / TIMING, {"command": command, "wall_s": timing or {}}))
        written.append(write_json(tmp / MANIFEST, manifest(tmp, command, provenance)))
    SWAPPED_IN.append(out)
    return [out / Path(p).relative_to(tmp) for p in written]


#: the --out folders written in this process, in order (an interrupt after one was swapped
#: in says so, gearwear.cli.app.main)
SWAPPED_IN: list[Path] = []
