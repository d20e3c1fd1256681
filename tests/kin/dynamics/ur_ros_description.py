"""Universal Robots' own description of the e-Series arms, as numbers: Universal_Robots_ROS2_Description
(github.com/UniversalRobots/Universal_Robots_ROS2_Description, commit 2221ec0f720fb1af99339eb891639b499b62f1da,
BSD-3-Clause), ``config/<arm>/default_kinematics.yaml`` (joint origins) and ``physical_parameters.yaml``
(masses, centres of mass, inertia rotations and tensors), copied by a script, unedited.  :func:`urdf_text`
writes the URDF that the description's ``urdf/ur_macro.xacro`` makes of them (base_link_inertia,
shoulder_link … wrist_3_link with their <inertial> elements; meshes, the base's cylinder and tool0 left out):
the independent model the bundled UR e-Series robot files are checked against."""
from __future__ import annotations

COMMIT = "2221ec0f720fb1af99339eb891639b499b62f1da"

#: per arm, per link shoulder … wrist_3: joint origin (x, y, z, roll, pitch, yaw) in the parent link,
#: mass kg, cog (m, link frame), inertia-frame rotation (roll, pitch, yaw) and tensor (ixx, iyy, izz, ixy, ixz,
#: iyz) kg·m² about the cog in that rotated frame
ARMS = {'ur3e': {'origins': [[0, 0, 0.15185, 0, 0, 0],
                      [0, 0, 0, 1.570796327, 0, 0],
                      [-0.24355, 0, 0, 0, 0, 0],
                      [-0.2132, 0, 0.13105, 0, 0, 0],
                      [0, -0.08535, -1.750557762378351e-11, 1.570796327, 0, 0],
                      [0, 0.0921, -1.8890025766262e-11, 1.570796326589793, 3.141592653589793, 3.141592653589793]],
          'mass': [1.98, 3.4445, 1.437, 0.871, 0.805, 0.261],
          'cog': [[0.0, 0.0, -0.02],
                  [-0.11355, 0.0, 0.1157],
                  [-0.1632, 0.0, 0.0238],
                  [0.0, -0.01, 0.0],
                  [0.0, 0.01, 0.0],
                  [0.0, 0.0, -0.02]],
          'rotation': [[0, 0, 0],
                       [0, 1.570796326794897, 0],
                       [0, 1.570796326794897, 0],
                       [0, 0, 0],
                       [0, 0, 0],
                       [0, 0, 0]],
          'tensor': [[0.008093166666666665, 0.008093166666666665, 0.005625, 0, 0, 0],
                     [0.021728491912499998, 0.021728491912499998, 0.00961875, 0, 0, 0],
                     [0.006544570199999999, 0.006544570199999999, 0.00354375, 0, 0, 0],
                     [0.0020849999999999996, 0.0020849999999999996, 0.00225, 0, 0, 0],
                     [0.0020849999999999996, 0.0020849999999999996, 0.00225, 0, 0, 0],
                     [0.00013626666666666665, 0.00013626666666666665, 0.0001792, 0, 0, 0]]},
 'ur5e': {'origins': [[0, 0, 0.1625, 0, 0, 0],
                      [0, 0, 0, 1.570796327, 0, 0],
                      [-0.425, 0, 0, 0, 0, 0],
                      [-0.3922, 0, 0.1333, 0, 0, 0],
                      [0, -0.0997, -2.044881182297852e-11, 1.570796327, 0, 0],
                      [0, 0.0996, -2.042830148012698e-11, 1.570796326589793, 3.141592653589793, 3.141592653589793]],
          'mass': [3.761, 8.058, 2.846, 1.37, 1.3, 0.365],
          'cog': [[0.0, -0.00193, -0.02561],
                  [-0.2125, 0.0, 0.11336],
                  [-0.2422, 0.0, 0.0265],
                  [0.0, -0.01634, -0.0018],
                  [0.0, 0.01634, -0.0018],
                  [0.0, 0.0, -0.001159]],
          'rotation': [[0, 0, 0],
                       [0, 1.570796326794897, 0],
                       [0, 1.570796326794897, 0],
                       [0, 0, 0],
                       [0, 0, 0],
                       [0, 0, 0]],
          'tensor': [[0.010267499999999999, 0.010267499999999999, 0.00666, 0, 0, 0],
                     [0.13388583541666665, 0.13388583541666665, 0.0151074, 0, 0, 0],
                     [0.03120936758333333, 0.03120936758333333, 0.004095, 0, 0, 0],
                     [0.0025599, 0.0025599, 0.0021942, 0, 0, 0],
                     [0.0025599, 0.0025599, 0.0021942, 0, 0, 0],
                     [9.890414008333333e-05, 9.890414008333333e-05, 0.0001321171875, 0, 0, 0]]},
 'ur10e': {'origins': [[0, 0, 0.1807, 0, 0, 0],
                       [0, 0, 0, 1.570796327, 0, 0],
                       [-0.6127, 0, 0, 0, 0, 0],
                       [-0.57155, 0, 0.17415, 0, 0, 0],
                       [0, -0.11985, -2.458164590756244e-11, 1.570796327, 0, 0],
                       [0,
                        0.11655,
                        -2.390480459346185e-11,
                        1.570796326589793,
                        3.141592653589793,
                        3.141592653589793]],
           'mass': [7.369, 13.051, 3.989, 2.1, 1.98, 0.615],
           'cog': [[0.021, -0.027, 0.0],
                   [-0.2327, 0.0, 0.158],
                   [-0.33155, 0.0, 0.068],
                   [0.0, -0.018, 0.007],
                   [0.0, 0.018, -0.007],
                   [0.0, 0.0, -0.026]],
           'rotation': [[1.570796326794897, 0, 0],
                        [0, 0, 0],
                        [0, 0, 0],
                        [1.570796326794897, 0, 0],
                        [-1.570796326794897, 0, 0],
                        [0, 0, 0]],
           'tensor': [[0.03408, 0.03529, 0.02156, 2e-05, -0.00425, 8e-05],
                      [0.02814, 0.77068, 0.76943, 5e-05, -0.01561, 2e-05],
                      [0.01014, 0.30928, 0.30646, 8e-05, 0.00916, 0.0],
                      [0.00296, 0.00222, 0.00258, -1e-05, 0.0, -0.00024],
                      [0.00296, 0.00222, 0.00258, -1e-05, 0.0, -0.00024],
                      [0.0004, 0.00041, 0.00034, 0.0, 0.0, 0.0]]},
 'ur16e': {'origins': [[0, 0, 0.1807, 0, 0, 0],
                       [0, 0, 0, 1.570796327, 0, 0],
                       [-0.4784, 0, 0, 0, 0, 0],
                       [-0.36, 0, 0.17415, 0, 0, 0],
                       [0, -0.11985, -2.458164590756244e-11, 1.570796327, 0, 0],
                       [0,
                        0.11655,
                        -2.390480459346185e-11,
                        1.570796326589793,
                        3.141592653589793,
                        3.141592653589793]],
           'mass': [7.369, 10.45, 4.321, 2.18, 2.033, 0.907],
           'cog': [[0.0, -0.03, -0.016],
                   [-0.1764, 0.0, 0.16],
                   [-0.166, 0.0, 0.065],
                   [0.0, -0.011, -0.009],
                   [0.0, 0.012, -0.018],
                   [0.0, 0.0, -0.044]],
           'rotation': [[1.570796326794897, 0, 0],
                        [0, 0, 0],
                        [0, 0, 0],
                        [1.570796326794897, 0, 0],
                        [-1.570796326794897, 0, 0],
                        [0, 0, 0]],
           'tensor': [[0.03351, 0.03374, 0.021, 2e-05, -1e-05, 0.00374],
                      [0.02796, 0.47558, 0.47635, -0.0001, -0.0072, 3e-05],
                      [0.01091, 0.1206, 0.11714, 6e-05, 0.01012, 1e-05],
                      [0.00609, 0.00245, 0.00579, -1e-05, 0.0, 0.00083],
                      [0.00389, 0.00219, 0.00363, -1e-05, 0.0, -0.00045],
                      [0.00117, 0.00118, 0.00084, 0.0, 0.0, 0.0]]}}

LINK_NAMES = ("shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link", "wrist_3_link")
JOINT_NAMES = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
               "wrist_3_joint")


def urdf_text(arm: str) -> str:
    """The URDF of ``arm`` (``ur3e`` … ``ur16e``) as ur_macro.xacro writes it: base_link → base_link_inertia
    (rpy 0 0 π) → the six revolute joints about z, each link's <inertial> at its cog with the rotation."""
    d = ARMS[arm]
    out = [f'<robot name="{arm}">', '  <link name="base_link"/>', '  <link name="base_link_inertia"/>',
           '  <joint name="base_link-base_link_inertia" type="fixed"><parent link="base_link"/>'
           '<child link="base_link_inertia"/><origin xyz="0 0 0" rpy="0 0 3.141592653589793"/></joint>']
    parent = "base_link_inertia"
    for k, (link, jname) in enumerate(zip(LINK_NAMES, JOINT_NAMES)):
        ixx, iyy, izz, ixy, ixz, iyz = d["tensor"][k]
        out += [f'  <link name="{link}"><inertial><mass value="{d["mass"][k]!r}"/>'
                f'<origin xyz="{" ".join(repr(float(x)) for x in d["cog"][k])}" '
                f'rpy="{" ".join(repr(float(x)) for x in d["rotation"][k])}"/>'
                f'<inertia ixx="{ixx!r}" iyy="{iyy!r}" izz="{izz!r}" ixy="{ixy!r}" ixz="{ixz!r}" iyz="{iyz!r}"/>'
                '</inertial></link>']
        x, y, z, r, p, yaw = d["origins"][k]
        out += [f'  <joint name="{jname}" type="revolute"><parent link="{parent}"/><child link="{link}"/>'
                f'<origin xyz="{x!r} {y!r} {z!r}" rpy="{r!r} {p!r} {yaw!r}"/><axis xyz="0 0 1"/>'
                '<limit lower="-6.283185307179586" upper="6.283185307179586" effort="0" velocity="0"/></joint>']
        parent = link
    out.append("</robot>")
    return "\n".join(out) + "\n"
