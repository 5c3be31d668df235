"""Which requests stop and which drive (``rtmu.protocol.motion``): the words the role gate goes by.

The module names ``ratioDrive`` by its data name, not by its payload class, so that every command's
parser (which loads the role gate) does not load the drive payloads; these tests hold the two equal
and the rule the same: a zero ``ratioDrive`` stops, a moving or undecodable one drives.
"""

from __future__ import annotations

from rtmu.protocol import motion
from rtmu.protocol.payloads.drive import RatioDrive


def test_the_ratio_drive_name_is_the_payloads_own() -> None:
    assert motion.RATIO_DRIVE == RatioDrive.DATA_NAME
    assert motion.is_motion(motion.RATIO_DRIVE)


def test_stop_and_a_zero_ratio_drive_only_stop() -> None:
    assert motion.is_stopping("stop", b"")
    assert motion.is_stopping("ratioDrive", RatioDrive(0.0, 0.0, 100.0).encode())
    assert motion.is_stopping("ratioDrive", RatioDrive(50.0, 10.0, 0.0).encode())  # no throttle: no motion


def test_a_moving_or_unreadable_ratio_drive_drives() -> None:
    assert not motion.is_stopping("ratioDrive", RatioDrive(0.0, 20.0, 100.0).encode())
    assert not motion.is_stopping("ratioDrive", RatioDrive(0.0, 0.0, 100.0, 30.0).encode())
    assert not motion.is_stopping("ratioDrive", b"\x01\x02")  # the server may read it as driving
    assert not motion.is_stopping("gotoGoal", b"Lab\x00")
