"""Plain-numpy products of module transforms, for tests only: they read a catalogue's TOML text with
tomllib and use its plain numbers — none of kin.modules — so that an assembled robot can be checked
against a second, simple computation.

Mating (docs/modules.md): the next module's input frame = previous output frame · Rz(twist); a joint
module's output = input · axis · Rz(q) (revolute) or Tz(q) (prismatic) · out; a link's or tool's
output = input · out, where a link given by ``length``/``offset``/``bend`` has out = T(offset, 0,
length) · Ry(bend); a base's output is its ``out`` in the world.  rpy is fixed-axis roll-pitch-yaw:
R = Rz(yaw) · Ry(pitch) · Rx(roll)."""
from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
FIXTURE = HERE / "fixture_catalogue.toml"
LENGTH = {"m": 1.0, "mm": 1e-3, "in": 0.0254}
ANGLE = {"rad": 1.0, "deg": np.pi / 180}


def rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1.0]])


def rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def tr(x=0.0, y=0.0, z=0.0):
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


class Plain:
    """A catalogue's modules as plain dicts, its frames as 4×4 numpy arrays (SI)."""

    def __init__(self, path: Path | str = FIXTURE):
        self.doc = tomllib.loads(Path(path).read_text())
        self.ls = LENGTH[self.doc["length_unit"]]
        self.as_ = ANGLE[self.doc["angle_unit"]]
        self.mod = {m["name"]: m for m in self.doc["modules"]}

    def frame(self, d: dict) -> np.ndarray:
        x, y, z = (v * self.ls for v in d.get("xyz", [0, 0, 0]))
        r, p, w = (v * self.as_ for v in d.get("rpy", [0, 0, 0]))
        return tr(x, y, z) @ rz(w) @ ry(p) @ rx(r)

    def out(self, m: dict) -> np.ndarray:
        if "out" in m:
            return self.frame(m["out"])
        return tr(m.get("offset", 0) * self.ls, 0, m["length"] * self.ls) @ ry(m.get("bend", 0) * self.as_)

    def parse(self, items: list[str]) -> tuple[list[str], list[float]]:
        names, twists = [], []
        for i, it in enumerate(items):
            name, _, t = it.partition("@")
            names.append(name)
            if i:
                twists.append(float(t or 0) * self.as_)
        return names, twists

    def frames(self, items: list[str], q) -> list[tuple[np.ndarray, np.ndarray, str]]:
        """(input frame, output frame, name) of every module, world, SI."""
        names, twists = self.parse(items)
        q = list(np.asarray(q, float))
        T, out = np.eye(4), []
        for i, name in enumerate(names):
            m = self.mod[name]
            Tin = T if i == 0 else T @ rz(twists[i - 1])
            if m["kind"] == "base":
                T = self.out(m)
            elif m["kind"] == "joint":
                v = q.pop(0) * (self.as_ if m["type"] == "revolute" else self.ls)
                move = rz(v) if m["type"] == "revolute" else tr(0, 0, v)
                T = Tin @ self.frame(m["axis"]) @ move @ self.frame(m["out"])
            else:
                T = Tin @ self.out(m)
            out.append((Tin, T, name))
        return out

    def tip(self, items: list[str], q) -> np.ndarray:
        return self.frames(items, q)[-1][1]

    def joints(self, items: list[str]) -> list[dict]:
        return [self.mod[n] for n in self.parse(items)[0] if self.mod[n]["kind"] == "joint"]

    def limits(self, items: list[str]) -> np.ndarray:
        """Joint limits in the file's units, one row per joint."""
        return np.array([m["limits"] for m in self.joints(items)], float)
