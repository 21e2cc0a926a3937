"""The thesis's ring rig (section 5.2): its station file, gripper and RAPID program, and its in-process demo
(`demo.py`, `twin demo`)."""
