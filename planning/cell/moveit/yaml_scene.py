"""Reading a ``moveit_msgs/PlanningScene`` written as YAML: :func:`parse_scene_yaml`.

Both ways tools write the message are read: ``rostopic echo`` / ``ros2 topic echo`` (a position as
``{x, y, z}``, an orientation as ``{x, y, z, w}``, a primitive's type as a number: 1 box, 2 sphere,
3 cylinder, 4 cone) and robowflex, which writes MotionBenchMaker's scenes (``[x, y, z]``,
``[x, y, z, w]``, ``type: box``).  What becomes the cell is ``world.collision_objects``:

* each object's ``id`` (kept as the obstacle's name), its ``header.frame_id``, its ``pose`` (MoveIt ≥
  1.1: the primitive and mesh poses are in the object's frame; absent before, which is the same as
  the identity), ``primitives`` with ``primitive_poses`` (box ``dimensions`` [x, y, z] full edge
  lengths, sphere [radius], cylinder and cone [height, radius]) and ``meshes`` with ``mesh_poses``
  (``vertices`` and ``triangles`` written in the file); a shape without a pose is at the identity,
  as MoveIt does;
* ``operation`` add (the default), or append for an id not seen before; remove and move edit a
  scene and are refused, as are planes (infinite), prisms and mesh ``resource`` files;
* an object's frame must be the planning frame (an empty ``frame_id``, the ``frame_id`` of the
  scene's ``fixed_frame_transforms``, or the one given as ``frame``) or a fixed frame of the scene
  (a ``child_frame_id`` of ``fixed_frame_transforms``, placed by its transform).

The rest — the robot's state, the allowed collision matrix, colours, octomaps, attached objects — is
not part of the cell; :attr:`Scene.notes` says what was left out that could matter.

The text is parsed by PyYAML's safe loader (no tags, no objects built from the file) after a scan
that refuses aliases (``*name``: a planning scene needs none, and aliases and merge keys can make a
small file expand without bound); only the fields above are walked, each bounded.
"""
from __future__ import annotations

import numpy as np
import yaml

from planning.cell.mesh import MAX_TRIANGLES
from planning.cell.moveit.scene import (
    SHAPE_DIMENSIONS,
    Scene,
    SceneBuilder,
    SceneObject,
    SceneShape,
    mesh_arrays,
    number,
    object_name,
    pose_matrix,
    positive_sizes,
)
from planning.cell.obstacles import MAX_VERTICES
from planning.errors import CellError

__all__ = ["parse_scene_yaml", "PLANNING_SCENE_KEYS", "OBJECT_KEYS", "PRIMITIVE_TYPES"]

PLANNING_SCENE_KEYS = {"name", "robot_state", "robot_model_name", "fixed_frame_transforms",
                       "allowed_collision_matrix", "link_padding", "link_scale", "object_colors", "world", "is_diff"}
WORLD_KEYS = {"collision_objects", "octomap"}
OBJECT_KEYS = {"header", "pose", "id", "type", "primitives", "primitive_poses", "meshes", "mesh_poses", "planes",
               "plane_poses", "subframe_names", "subframe_poses", "operation"}
#: shape_msgs/SolidPrimitive's type numbers
PRIMITIVE_TYPES = {1: "box", 2: "sphere", 3: "cylinder", 4: "cone"}
_OPERATIONS = {0: "add", 1: "remove", 2: "append", 3: "move"}
_REQUEST_KEYS = {"start_state", "goal_constraints", "group_name", "planner_id", "workspace_parameters"}
_FORMAT = "PlanningScene YAML"


def _keys(label: str, table: dict, allowed: set[str]) -> None:
    unknown = sorted(str(k) for k in set(table) - allowed)
    if unknown:
        raise CellError(f"{label}: unknown field(s) {', '.join(u[:40] for u in unknown[:5])}; allowed: "
                        f"{', '.join(sorted(allowed))}")


def _load(text: str, where: str):
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    try:
        for event in yaml.parse(text, Loader=loader):
            if isinstance(event, yaml.AliasEvent):
                line = event.start_mark.line + 1 if event.start_mark is not None else "?"
                raise CellError(f"{where}: line {line}: a YAML alias (*{str(event.anchor)[:40]}); a planning scene "
                                f"needs none, and they are not read")
        return yaml.load(text, Loader=loader)
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        at = f"line {mark.line + 1}: " if mark is not None else ""
        what = ", ".join(str(x) for x in (e.context, e.problem) if x)
        raise CellError(f"{where}: not valid YAML ({at}{what[:200]})") from None
    except yaml.YAMLError as e:
        raise CellError(f"{where}: not valid YAML ({str(e).splitlines()[0][:160] if str(e) else type(e).__name__})") \
            from None
    except RecursionError:
        raise CellError(f"{where}: not read: its YAML nests too deep") from None


def _vector(v, names: tuple[str, ...], label: str, what: str) -> list[float]:
    """A vector given as a list ``[x, y, z]`` or a map ``{x: …, y: …, z: …}``."""
    if isinstance(v, dict):
        if set(v) != set(names):
            raise CellError(f"{label}: must have the fields {', '.join(names)} ({what}), not {sorted(map(str, v))}")
        v = [v[n] for n in names]
    if not isinstance(v, list) or len(v) != len(names):
        raise CellError(f"{label}: must be {len(names)} numbers [{', '.join(names)}] ({what}), not {str(v)[:80]}")
    return [number(x, label, what) for x in v]


def _pose(p, label: str) -> np.ndarray:
    """A geometry_msgs/Pose; absent → identity; an absent orientation is MoveIt's empty one (identity)."""
    if p is None:
        return np.eye(4)
    if not isinstance(p, dict):
        raise CellError(f"{label}: must be a pose {{position, orientation}}, not {type(p).__name__}")
    _keys(label, p, {"position", "orientation"})
    pos = _vector(p["position"], ("x", "y", "z"), f"{label}.position", "m") if p.get("position") is not None \
        else [0.0, 0.0, 0.0]
    quat = _vector(p["orientation"], ("x", "y", "z", "w"), f"{label}.orientation", "a quaternion") \
        if p.get("orientation") is not None else [0.0, 0.0, 0.0, 0.0]
    return pose_matrix(pos, quat, label)


def _list(o: dict, key: str, label: str) -> list:
    v = o.get(key)
    if v is None:
        return []
    if not isinstance(v, list):
        raise CellError(f"{label}: {key}: must be a list, not {type(v).__name__}")
    return v


def _primitive(prim, pose, label: str) -> SceneShape:
    if not isinstance(prim, dict):
        raise CellError(f"{label}: must be a map {{type, dimensions}}, not {type(prim).__name__}")
    _keys(label, prim, {"type", "dimensions", "polygon"})
    t = prim.get("type")
    kind = PRIMITIVE_TYPES.get(t) if isinstance(t, int) and not isinstance(t, bool) else \
        t.strip().lower() if isinstance(t, str) else None
    if kind == "prism" or (isinstance(t, int) and t == 5):
        raise CellError(f"{label}: type: a prism is not read; allowed: box, sphere, cylinder, cone (or 1 to 4)")
    if kind not in ("box", "sphere", "cylinder", "cone"):
        raise CellError(f"{label}: type {str(t)[:40]!r} unknown; allowed: box, sphere, cylinder, cone (or 1 to 4)")
    dims = prim.get("dimensions")
    need = {"box": "[x, y, z] (full edge lengths, m)", "sphere": "[radius] (m)",
            "cylinder": "[height, radius] (m)", "cone": "[height, radius] (m)"}[kind]
    n = {"box": 3, "sphere": 1, "cylinder": 2, "cone": 2}[kind]
    if not isinstance(dims, list) or len(dims) != n:
        raise CellError(f"{label}: dimensions: a {kind} has {n} {need}, not {str(dims)[:80]}")
    d = [number(x, f"{label}: dimensions", need) for x in dims]
    if kind in ("cylinder", "cone"):
        d = [d[1], d[0]]                                     # the message's [height, radius] → radius, length
    size = positive_sizes(d, SHAPE_DIMENSIONS[kind], f"{label}: dimensions")
    return SceneShape(kind, size, _pose(pose, f"{label}: pose"))


def _index(i, label: str) -> int:
    if isinstance(i, bool) or not isinstance(i, int):
        raise CellError(f"{label}: vertex indices must be whole numbers, not {str(i)[:40]!r}")
    return i


def _mesh(mesh, pose, label: str) -> SceneShape:
    if not isinstance(mesh, dict):
        raise CellError(f"{label}: must be a map {{vertices, triangles}}, not {type(mesh).__name__}")
    if "resource" in mesh:
        raise CellError(f"{label}: a mesh resource ({str(mesh['resource'])[:80]!r}) is not read; only meshes written "
                        f"in the scene (vertices, triangles) are: export it to STL and add a mesh obstacle to the cell")
    _keys(label, mesh, {"vertices", "triangles"})
    V, F = mesh.get("vertices"), mesh.get("triangles")
    if not isinstance(V, list) or not isinstance(F, list):
        raise CellError(f"{label}: vertices and triangles must be lists")
    if len(V) > MAX_VERTICES:
        raise CellError(f"{label}: {len(V)} vertices; at most {MAX_VERTICES}")
    if len(F) > MAX_TRIANGLES:
        raise CellError(f"{label}: {len(F)} triangles; at most {MAX_TRIANGLES} (simplify the mesh)")
    vertices = [_vector(v, ("x", "y", "z"), f"{label}: vertices[{j}]", "m") for j, v in enumerate(V)]
    triangles = []
    for j, t in enumerate(F):
        if isinstance(t, dict):
            _keys(f"{label}: triangles[{j}]", t, {"vertex_indices"})
            t = t.get("vertex_indices")
        if not isinstance(t, list) or len(t) != 3:
            raise CellError(f"{label}: triangles[{j}]: must be 3 vertex indices, not {str(t)[:60]}")
        triangles.append([_index(i, f"{label}: triangles[{j}]") for i in t])
    V, F = mesh_arrays(vertices, triangles, label)
    return SceneShape("mesh", (), _pose(pose, f"{label}: pose"), V, F)


def _frames(doc: dict, where: str, frame: str | None) -> tuple[set[str], dict[str, np.ndarray]]:
    """The planning frame's names and the fixed frames (name → 4×4 in the planning frame)."""
    planning = {frame.lstrip("/")} if frame else set()
    fixed: dict[str, np.ndarray] = {}
    ffts = doc.get("fixed_frame_transforms") or []
    if not isinstance(ffts, list):
        raise CellError(f"{where}: fixed_frame_transforms: must be a list")
    for j, t in enumerate(ffts[:1000]):
        label = f"{where}: fixed_frame_transforms[{j}]"
        if not isinstance(t, dict):
            raise CellError(f"{label}: must be a map {{header, child_frame_id, transform}}")
        header = t.get("header") or {}
        parent = header.get("frame_id", "") if isinstance(header, dict) else ""
        child = t.get("child_frame_id", "")
        if not isinstance(parent, str) or not isinstance(child, str):
            raise CellError(f"{label}: frame names must be strings")
        if parent.strip("/"):
            planning.add(parent.lstrip("/"))
        tf = t.get("transform") or {}
        if not isinstance(tf, dict):
            raise CellError(f"{label}: transform: must be a map {{translation, rotation}}")
        tr = _vector(tf["translation"], ("x", "y", "z"), f"{label}: transform.translation", "m") \
            if tf.get("translation") is not None else [0.0, 0.0, 0.0]
        rot = _vector(tf["rotation"], ("x", "y", "z", "w"), f"{label}: transform.rotation", "a quaternion") \
            if tf.get("rotation") is not None else [0.0, 0.0, 0.0, 0.0]
        if child.strip("/"):
            fixed[child.lstrip("/")] = pose_matrix(tr, rot, label)
    return planning, fixed


def _object_frame(header, planning: set[str], fixed: dict, label: str) -> np.ndarray:
    if header is None:
        return np.eye(4)
    if not isinstance(header, dict):
        raise CellError(f"{label}: header: must be a map {{frame_id, …}}, not {type(header).__name__}")
    f = header.get("frame_id", "")
    if not isinstance(f, str):
        raise CellError(f"{label}: header.frame_id: must be a string, not {type(f).__name__}")
    f = f.strip().lstrip("/")
    if not f or f in planning:
        return np.eye(4)
    if f in fixed:
        return fixed[f]
    known = sorted(planning) + sorted(fixed)
    raise CellError(f"{label}: header.frame_id {f[:60]!r} is neither the planning frame nor a fixed frame of the "
                    f"scene ({', '.join(known) if known else 'the scene names none'}); an object placed in a robot "
                    f"link's frame moves with the robot and is not read — if {f[:60]!r} is the planning frame, say "
                    f"so (rmt import-scene --frame)")


def _object(o, k: int, where: str, builder: SceneBuilder, planning: set[str], fixed: dict) -> None:
    label = f"{where}: object {k}"
    if not isinstance(o, dict):
        raise CellError(f"{label}: must be a map (a moveit_msgs/CollisionObject), not {type(o).__name__}")
    name = object_name(o.get("id"), label)
    label = f"{where}: object {k} ({name!r})"
    _keys(label, o, OBJECT_KEYS)
    op = o.get("operation", 0)
    op = _OPERATIONS.get(op) if isinstance(op, int) and not isinstance(op, bool) else \
        op.strip().lower() if isinstance(op, str) else None
    if op not in _OPERATIONS.values():
        raise CellError(f"{label}: operation {str(o.get('operation'))[:40]!r} unknown; allowed: add (0), append (2)")
    if op in ("remove", "move") or (op == "append" and name in builder.where):
        raise CellError(f"{label}: operation {op} edits an object of a scene; rmt reads whole scenes (each object "
                        f"once, operation add)")
    builder.check_id(name, k, label)
    frame = _object_frame(o.get("header"), planning, fixed, label)
    pose = _pose(o.get("pose"), f"{label}: pose")
    shapes = []
    for key, poses_key, make in (("primitives", "primitive_poses", _primitive), ("meshes", "mesh_poses", _mesh)):
        items, poses = _list(o, key, label), _list(o, poses_key, label)
        if len(poses) > len(items):
            raise CellError(f"{label}: {len(poses)} {poses_key} for {len(items)} {key}")
        if len(items) > 1000:
            raise CellError(f"{label}: {len(items)} {key}; at most 1000")
        shapes += [make(item, poses[j] if j < len(poses) else None, f"{label}: {key}[{j}]")
                   for j, item in enumerate(items)]
    if _list(o, "planes", label):
        raise CellError(f"{label}: planes: an infinite plane is not an obstacle of a cell; model it as a box")
    builder.add(SceneObject(name, frame @ pose, tuple(shapes)), k, label)


def _notes(doc: dict, world: dict, names: set[str]) -> list[str]:
    """What the scene holds that the cell leaves out and that could matter (read defensively: these
    fields are not part of the cell, so they are not checked)."""
    notes = []
    state = doc.get("robot_state")
    if isinstance(state, dict):
        attached = state.get("attached_collision_objects")
        if isinstance(attached, list) and attached:
            notes.append(f"robot_state: {len(attached)} attached object(s) not imported (they move with the robot; "
                         f"give the tool's shape as [[tool]] tables)")
        multi = state.get("multi_dof_joint_state")
        tfs = multi.get("transforms") if isinstance(multi, dict) else None
        if isinstance(tfs, list):
            for t in tfs[:100]:
                tr = t.get("translation") if isinstance(t, dict) else None
                vals = list(tr.values()) if isinstance(tr, dict) else tr if isinstance(tr, list) else []
                if any(isinstance(v, (int, float)) and not isinstance(v, bool) and v != 0 for v in vals):
                    notes.append("robot_state: a multi-DOF joint (a virtual joint?) moves the robot from the planning "
                                 "frame's origin; the cell places the robot by its [robot] table")
                    break
    acm = doc.get("allowed_collision_matrix")
    entries = acm.get("entry_names") if isinstance(acm, dict) else None
    if isinstance(entries, list):
        objects = sorted({e for e in entries[:10_000] if isinstance(e, str) and " ".join(e.split()) in names})
        if objects:
            notes.append(f"allowed_collision_matrix: entries of objects ({', '.join(objects[:5])}) not imported; "
                         f"say who may touch them with ignore lists or [allow] pairs")
    octomap = world.get("octomap")
    data = octomap.get("octomap", {}).get("data") if isinstance(octomap, dict) and \
        isinstance(octomap.get("octomap"), dict) else None
    if data:
        notes.append("world.octomap: an octomap is not imported (give the points as a point_cloud obstacle)")
    padding = doc.get("link_padding")
    if isinstance(padding, list) and any(isinstance(p, dict) and p.get("padding") for p in padding[:1000]):
        notes.append("link_padding: MoveIt's padding of the robot's links is not imported (rmt --clearance D asks "
                     "for clearance)")
    return notes


def parse_scene_yaml(text: str, where: str = "scene", frame: str | None = None) -> Scene:
    """The :class:`Scene` of a PlanningScene YAML text; ``where`` names it in messages; ``frame``: the
    planning frame's name, when objects name it in their ``header.frame_id`` and the scene's
    ``fixed_frame_transforms`` do not."""
    doc = _load(text, where)
    if not isinstance(doc, dict):
        raise CellError(f"{where}: not a moveit_msgs/PlanningScene (a YAML map with world.collision_objects), but "
                        f"{'an empty file' if doc is None else 'a ' + type(doc).__name__}")
    if "world" not in doc and set(map(str, doc)) & _REQUEST_KEYS:
        raise CellError(f"{where}: a motion plan request, not a planning scene (MotionBenchMaker's scenes are "
                        f"sceneNNNN.yaml, beside requestNNNN.yaml)")
    _keys(where, doc, PLANNING_SCENE_KEYS)
    planning, fixed = _frames(doc, where, frame)
    world = doc.get("world") or {}
    if not isinstance(world, dict):
        raise CellError(f"{where}: world: must be a map {{collision_objects, octomap}}")
    _keys(f"{where}: world", world, WORLD_KEYS)
    objects = world.get("collision_objects") or []
    if not isinstance(objects, list):
        raise CellError(f"{where}: world.collision_objects: must be a list")
    builder = SceneBuilder(where)
    builder.count(len(objects))
    for k, o in enumerate(objects, 1):
        _object(o, k, where, builder, planning, fixed)
    name = doc.get("name")
    model = doc.get("robot_model_name")
    return Scene(name if isinstance(name, str) else "", tuple(builder.objects), _FORMAT, where,
                 tuple(_notes(doc, world, set(builder.where))), model if isinstance(model, str) else "")
