"""What a station file falls back on or chooses from, defined once in a module that imports nothing.

`twin.core.station` reads station files with these; the robot's kinematics, the watchdog, the Modbus
server and the offline RAPID runner take them from here without loading the station reader.
"""

DEFAULT_STEP = 0.012  # s: a station's simulation step when it names none (the robot controller ticks with it)
ARM_JOINTS = ("joint_1", "joint_2", "joint_3", "joint_4", "joint_5", "joint_6")  # [robot] joints: base to flange
SAFE_STATES = ("hold", "open", "stop")  # [watchdog] safe_state: what the gripper does when the PLC goes quiet
