"""The bundled example tool paths (CSV of poses or TOML of line/arc segments, in their robot's file
units): :func:`bundled_toolpaths` lists their names, :func:`toolpath_file` finds one by name.

    from planning.toolpath import load_toolpath
    from studies.toolpaths import toolpath_file
    path = load_toolpath(toolpath_file("scara_line"), kin.load_robot("scara_rrp"))
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["TOOLPATH_DIR", "bundled_toolpaths", "toolpath_file"]

TOOLPATH_DIR = Path(__file__).parent


def bundled_toolpaths() -> list[str]:
    """Names of the bundled example tool paths."""
    return sorted(p.stem for p in TOOLPATH_DIR.glob("*") if p.suffix in (".toml", ".csv"))


def toolpath_file(arg: str) -> Path:
    """A tool-path argument → an existing file: a path, or the name of a bundled example."""
    from planning.toolpath import ToolPathError
    p = Path(arg)
    if p.is_file():
        return p
    if p.suffix or "/" in arg:
        raise ToolPathError("no such tool-path file", arg)
    for ext in (".toml", ".csv"):
        if (TOOLPATH_DIR / f"{arg}{ext}").is_file():
            return TOOLPATH_DIR / f"{arg}{ext}"
    raise ToolPathError(f"no such tool-path file or bundled tool path; bundled: {', '.join(bundled_toolpaths())} "
                        "(or give a path to a .csv or .toml file)", arg)
