"""Five grippers nobody tuned (issue 18), written from docs/station-format.md alone, each a station folder here:

- `newcomer_2f`: a newcomer's 2-finger gripper on the shipped arm, two independent 40 N prismatic fingers of 20 g,
  a 30 mm can (42 g); variants on a 36 g box (`newcomer_2f_box`) and a 300 g steel cylinder (`newcomer_2f_steel`);
- `parallel_200n`: a 200 N parallel gripper, one input, the second jaw a 1:1 mimic (100 N per jaw), a 0.34 kg block;
- `revolute_chuck`: a 3-jaw chuck of 2 N m revolute levers on a 0.23 kg disc from outside, and into the bore of a
  2.2 kg ring (`revolute_chuck_bore`);
- `light_5n`: a gantry lift carrying two 5 N fingers of 8 g, a 10 g cube;
- `sloppy_inertia`: a CAD export with 1 kg m^2 inertias on 50 g fingers, two 50 N fingers, a 0.14 kg cylinder;
- `pr2_mesh`: pybullet_data's PR2 gripper, two revolute fingers with mesh (STL) proximal links, given 2 N m each in
  place of the URDF's 1000 N m placeholder, closing their pads on a 20 mm peg;
- `heavy_jaws_light_can`: 2 kg jaws at 100 N on a 50 g can (the part 40 times lighter than either jaw);
- `round_pads`: fingers whose pads are URDF cylinders (8 mm radius), 60 N each, on a 40 mm aluminium cube;
- `angular_bare`: two revolute jaws of 0.4 N m as a CAD export leaves them (one with no `<inertial>`, the other a
  1 kg m^2 placeholder on 30 g), pinching a 16 mm cube of 10 g;
- `knuckle_2f`: two fingers of two knuckles each (a driven proximal joint, a mimic distal one), 1 N m, on a 90 g can;
- `ram_press`: one finger, a 50 N ram moving down, pressing a 200 g block onto an anvil (a fixture);
- `light_jaws_heavy_block`: 20 g jaws at 300 N on a 4 kg steel block (the part 200 times heavier than either jaw);
- `watch_2n`: a watchmaker's 2 N jaws of 1.4 g with a 5 mm stroke on a 1.7 g wheel, their range ending 1 mm past it;
- `uneven_speeds`: 50 N jaws at 80 and 10 mm/s on a centred 64 g cube, which the fast one pushes 7.8 mm over;
- `arm_block_2kg`: two 80 N jaws on the shipped arm holding a 1.98 kg steel block by its sides (3.3 times its weight);
- `vgroove_pin`: 20 N jaws whose pads are 90 degree V-grooves of two flanks, on a 20 mm pin.

`GRIPPERS` maps each name to its folder (what `twin check` and `Twin.from_station` take); `GRIPS` says how each
grips its part: the setpoints that close every finger past it (so each presses with its whole drive effort), and
what statics says each finger presses with then (N, or N m for a revolute finger).
"""
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
NAMES = ("newcomer_2f", "newcomer_2f_box", "newcomer_2f_steel", "parallel_200n", "revolute_chuck",
         "revolute_chuck_bore", "light_5n", "sloppy_inertia", "pr2_mesh", "heavy_jaws_light_can", "round_pads",
         "angular_bare", "knuckle_2f", "ram_press", "light_jaws_heavy_block", "watch_2n",
         "uneven_speeds", "arm_block_2kg", "vgroove_pin")
GRIPPERS = {name: HERE / name for name in NAMES}


@dataclass(frozen=True)
class Grip:
    part: str
    close: dict  # input -> setpoint past the part (every finger at its force limit)
    force: dict  # finger -> what statics says it presses with (its drive's effort; half of it for a 1:1 mimic pair)
    closing: str = "outside"  # "outside" (status 2 when stalled) or "inside" (into a bore: status 1)


GRIPS = {  # every finger closed to its range's end: well past the part, so each presses with its drive's effort
    "newcomer_2f": Grip("can", {"finger_left": 0.0, "finger_right": 0.0}, {"finger_left": 40.0, "finger_right": 40.0}),
    "newcomer_2f_box": Grip("box", {"finger_left": 0.0, "finger_right": 0.0},
                            {"finger_left": 40.0, "finger_right": 40.0}),
    "newcomer_2f_steel": Grip("slug", {"finger_left": 0.0, "finger_right": 0.0},
                              {"finger_left": 40.0, "finger_right": 40.0}),
    "parallel_200n": Grip("block", {"jaw_a": 0.0}, {"jaw_a": 100.0, "jaw_b": 100.0}),
    "revolute_chuck": Grip("disc", {"jaw_1": -0.35, "jaw_2": -0.35, "jaw_3": -0.35},
                           {"jaw_1": 2.0, "jaw_2": 2.0, "jaw_3": 2.0}),
    "revolute_chuck_bore": Grip("ring", {"jaw_1": 0.35, "jaw_2": 0.35, "jaw_3": 0.35},
                                {"jaw_1": 2.0, "jaw_2": 2.0, "jaw_3": 2.0}, "inside"),
    "light_5n": Grip("cube", {"jaw_left": 0.0, "jaw_right": 0.0}, {"jaw_left": 5.0, "jaw_right": 5.0}),
    "sloppy_inertia": Grip("cylinder", {"finger_1_link": 0.0, "finger_2_link": 0.0},
                           {"finger_1_link": 50.0, "finger_2_link": 50.0}),
    "pr2_mesh": Grip("peg", {"left_gripper": 0.0, "right_gripper": 0.0}, {"left_gripper": 2.0, "right_gripper": 2.0}),
    "heavy_jaws_light_can": Grip("can", {"jaw_l": 0.05, "jaw_r": 0.05}, {"jaw_l": 100.0, "jaw_r": 100.0}),
    "round_pads": Grip("cube", {"pad_l": 0.04, "pad_r": 0.04}, {"pad_l": 60.0, "pad_r": 60.0}),
    "angular_bare": Grip("cube", {"jaw_l": 0.5, "jaw_r": 0.5}, {"jaw_l": 0.4, "jaw_r": 0.4}),
    # (the finger's own joint is the distal knuckle: the torque about it by virtual work, gripper.urdf's comment)
    "knuckle_2f": Grip("can", {"prox_l": 0.6, "prox_r": 0.6}, {"dist_l": 0.215, "dist_r": 0.215}),
    "ram_press": Grip("block", {"ram": 0.08}, {"ram": 51.96}),  # (the drive's 50 N and the ram's weight)
    "light_jaws_heavy_block": Grip("block", {"jaw_l": 0.05, "jaw_r": 0.05}, {"jaw_l": 300.0, "jaw_r": 300.0}),
    "watch_2n": Grip("wheel", {"jaw_l": 0.005, "jaw_r": 0.005}, {"jaw_l": 2.0, "jaw_r": 2.0}),
    "uneven_speeds": Grip("cube", {"jaw_l": 0.046, "jaw_r": 0.046}, {"jaw_l": 50.0, "jaw_r": 50.0}),
    # (along each jaw's axis: its flanks' normal forces, at 45 degrees to it, sum to more)
    "vgroove_pin": Grip("pin", {"jaw_l": 0.035, "jaw_r": 0.035}, {"jaw_l": 20.0, "jaw_r": 20.0}),
}


def station(name: str) -> Path:
    """The station folder of test gripper `name`."""
    return GRIPPERS[name]
