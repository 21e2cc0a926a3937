"""Small URDFs and stations written under tmp_path, for tests of what the twin accepts and refuses."""
from pathlib import Path

INERTIAL = ('<inertial><origin xyz="0 0 0"/><mass value="0.05"/>'
            '<inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>')


def link(name: str, collision: bool = True, geometry: str = '<box size="0.01 0.02 0.05"/>') -> str:
    col = f"<collision><geometry>{geometry}</geometry></collision>" if collision else ""
    return f'<link name="{name}">{INERTIAL}<visual><geometry>{geometry}</geometry></visual>{col}</link>'


def joint(name: str, jtype: str, parent: str, child: str, limit: str = 'lower="0" upper="0.04"', extra: str = "",
          axis: str = "1 0 0") -> str:
    lim = f'<limit {limit} effort="10" velocity="0.1"/>' if limit else ""
    return (f'<joint name="{name}" type="{jtype}"><parent link="{parent}"/><child link="{child}"/>'
            f'<axis xyz="{axis}"/>{lim}{extra}</joint>')


def urdf(path: Path, *parts: str, name: str = "g") -> Path:
    path.write_text(f'<?xml version="1.0"?>\n<robot name="{name}">\n' + "\n".join(parts) + "\n</robot>\n")
    return path


def two_jaws(path: Path, a: str = "jaw_a", b: str = "jaw_b", collision: bool = True) -> Path:
    """A parallel gripper: base `palm`, two prismatic jaws, the second mimicking the first."""
    return urdf(path, link("palm", geometry='<box size="0.1 0.04 0.02"/>'),
                joint("ja", "prismatic", "palm", a), link(a, collision),
                joint("jb", "prismatic", "palm", b, extra='<mimic joint="ja"/>', axis="-1 0 0"), link(b, collision))


def block_and_floor(xyz: str) -> str:
    """The station tail every test station shares: a 30 x 30 x 40 mm block (the target) at `xyz`, a floor."""
    return f"""[[targets]]
name = "block"
shape = "box"
size = [0.03, 0.03, 0.04]
xyz = [{xyz}]
density = 1000.0

[[fixtures]]
name = "floor"
shape = "plane"
"""


STATION = """[station]
name = "t"

[gripper]
urdf = "{urdf}"
mount = { xyz = [0.0, 0.0, 0.3], rpy_deg = [180.0, 0.0, 0.0] }
always_active = true
{gripper_extra}

""" + block_and_floor("0.0, 0.0, 0.02")


def station(folder: Path, gripper_urdf: Path, gripper_extra: str = "", text: str | None = None) -> Path:
    """A station with the gripper fixed in the world above a block; returns the station file."""
    path = folder / "station.toml"
    path.write_text((text or STATION).replace("{urdf}", str(gripper_urdf)).replace("{gripper_extra}", gripper_extra))
    return path
