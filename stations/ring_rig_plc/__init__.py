"""The ring rig with its gripper under a PLC: the station, its robot program, the gripper PLC (`plc_logic.py`),
the networked demo (`demo.py`, `plc demo`) and its commissioning campaign."""
