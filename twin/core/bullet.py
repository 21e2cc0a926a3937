"""pybullet, imported once without its banner.

pybullet's C module prints "pybullet build time: ..." (on stderr) when first imported, which lands in the
middle of a command's output (a demo's narration, `--json`). Modules that need pybullet import it from here.
"""
from __future__ import annotations

from .native_output import quiet_native_output

with quiet_native_output(stdout=True, stderr=True):
    import pybullet  # noqa: E402
    from pybullet_utils.bullet_client import BulletClient  # noqa: E402

__all__ = ["BulletClient", "pybullet"]
