"""The simulation core: station, mechanism, physics world, gripper logic, robot, signal table.

It imports pybullet and numpy, never sockets, asyncio or time: its clock is step count x dt.
"""
