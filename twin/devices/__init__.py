"""Device profiles: the twin's gripper answering as a real gripper does (Robotiq 2F-85, 3-Finger) on Modbus.

`robotiq` is the gripper's own controller as a twin device (no protocol), `mapping` reads the station's
`[profile]` table. `twin.frontends.modbus.profile` serves the gripper's registers at their published addresses
(`twin serve --profile`). This package imports only `twin.core`.
"""
