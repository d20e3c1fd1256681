"""Hand-written planning scenes shared by the MoveIt import tests (not a test module): the same world in
the three forms MoveIt writes, and where its shapes must end up (computed here with scipy's rotations,
not rmtkit's)."""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

#: rostopic-echo style: maps for vectors, primitive types as numbers, frames named
YAML_ECHO = """
name: lab
robot_model_name: fanuc_lrmate200id
robot_state:
  joint_state: {name: [J1], position: [0.0]}
fixed_frame_transforms:
  - header: {frame_id: base_link}
    child_frame_id: world
    transform:
      translation: {x: 0.0, y: 0.0, z: -0.5}
      rotation: {x: 0.0, y: 0.0, z: 0.0, w: 1.0}
world:
  collision_objects:
    - header: {frame_id: world}
      id: table
      pose:
        position: {x: 0.6, y: 0.0, z: 0.4}
        orientation: {x: 0.0, y: 0.0, z: 0.7071067811865476, w: 0.7071067811865476}
      primitives:
        - {type: 1, dimensions: [1.2, 0.8, 0.04]}
        - {type: 3, dimensions: [0.4, 0.02]}
      primitive_poses:
        - {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {x: 0, y: 0, z: 0, w: 1}}
        - {position: {x: 0.5, y: 0.3, z: -0.2}, orientation: {x: 0, y: 0, z: 0, w: 1}}
      operation: 0
    - header: {frame_id: /base_link}
      id: base
      primitives: [{type: 2, dimensions: [0.05]}]
      primitive_poses: [{position: {x: 0.3, y: 0.2, z: 0.1}, orientation: {x: 0, y: 0, z: 0, w: 0}}]
    - id: wedge
      meshes:
        - vertices: [{x: 0, y: 0, z: 0}, {x: 0.1, y: 0, z: 0}, {x: 0, y: 0.1, z: 0}, {x: 0, y: 0, z: 0.1}]
          triangles: [{vertex_indices: [0, 1, 2]}, {vertex_indices: [0, 1, 3]}, {vertex_indices: [0, 2, 3]},
                      {vertex_indices: [1, 2, 3]}]
      mesh_poses: [{position: {x: 0.5, y: -0.3, z: 0.2}, orientation: {x: 0, y: 0, z: 0, w: 1}}]
      operation: 2
    - id: funnel
      primitives: [{type: cone, dimensions: [0.3, 0.1]}]
      primitive_poses: [{position: [1.0, 1.0, 0.15], orientation: [0.3826834323650898, 0, 0, 0.9238795325112867]}]
"""

#: MoveIt ≥ 1.1.10's .scene text of the same world (in the planning frame: the table 0.5 m lower); 6 digits
#: as MoveIt writes them; colours present, one absent (hand-edited)
TEXT_NOETIC = """lab
* table
0.6 0 -0.1
0 0 0.707107 0.707107
2
box
1.2 0.8 0.04
0 0 0
0 0 0 1
0 0 0 0
cylinder
0.02 0.4
0.5 0.3 -0.2
0 0 0 1
0 0 0 0
0
* base
0 0 0
0 0 0 1
1
sphere
0.05
0.3 0.2 0.1
0 0 0 1
0.5 0.5 0.5 1
1
grasp
0 0 0.1
0 0 0 1
* wedge
0.5 -0.3 0.2
0 0 0 1
1
mesh
4 4
0 0 0
0.1 0 0
0 0.1 0
0 0 0.1
0 1 2
0 1 3
0 2 3
1 2 3
0 0 0
0 0 0 1
0
* funnel
1 1 0.15
0.382683 0 0 0.92388
1
cone
0.1 0.3
0 0 0
0 0 0 1
0 0 0 0
0
.
"""

#: MoveIt ≤ 1.1.9 (Melodic): no object poses, no subframes; shape poses in the planning frame
TEXT_MELODIC = """(noname)
* table
2
box
1.2 0.8 0.04
0.6 0 -0.1
0 0 0.707107 0.707107
0 0 0 0
cylinder
0.02 0.4
0.3 0.5 -0.3
0 0 0.707107 0.707107
0 0 0 0
* base
1
sphere
0.05
0.3 0.2 0.1
0 0 0 1
0 0 0 0
* wedge
1
mesh
4 4
0 0 0
0.1 0 0
0 0.1 0
0 0 0.1
0 1 2
0 1 3
0 2 3
1 2 3
0.5 -0.3 0.2
0 0 0 1
* funnel
1
cone
0.1 0.3
1 1 0.15
0.382683 0 0 0.92388
0 0 0 0
.
"""


def _T(xyz, quat_xyzw=(0, 0, 0, 1)) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat(quat_xyzw).as_matrix()
    T[:3, 3] = xyz
    return T


_YAW90 = (0, 0, np.sqrt(0.5), np.sqrt(0.5))
#: (object name, kind, sizes (m), 4×4 in the planning frame) of every shape of the world above
EXPECTED = [
    ("table", "box", (1.2, 0.8, 0.04), _T((0.6, 0, -0.1), _YAW90)),
    ("table", "cylinder", (0.02, 0.4), _T((0.6, 0, -0.1), _YAW90) @ _T((0.5, 0.3, -0.2))),
    ("base", "sphere", (0.05,), _T((0.3, 0.2, 0.1))),
    ("wedge", "mesh", (), _T((0.5, -0.3, 0.2))),
    ("funnel", "cone", (0.1, 0.3), _T((1.0, 1.0, 0.15), (np.sin(np.pi / 8), 0, 0, np.cos(np.pi / 8)))),
]
WEDGE_VERTICES = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]])
WEDGE_TRIANGLES = np.array([[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]])


def shapes_in_planning_frame(scene) -> list[tuple[str, str, tuple, np.ndarray]]:
    """(object name, kind, size, 4×4 in the planning frame) of every shape of a Scene."""
    return [(ob.name, s.kind, s.size, ob.pose @ s.pose) for ob in scene.objects for s in ob.shapes]
