"""The simulated robot's numbers: a Pioneer 3-DX as ARIA and MobileSim describe it.

Sources (facts, written down here by us):

* ARIA's ``params/p3dx.p``: class ``Pioneer``, subclass ``p3dx``, radius 250 mm,
  width 425 mm, length 511 mm (210 mm in front of the centre of rotation,
  301 mm behind), absolute maxima 2200 mm/s and 500 deg/s, and the 16 sonar
  discs (x, y in mm, heading in degrees).
* MobileSim's Pioneer model: acceleration 300 mm/s², rotational acceleration
  1.74 rad/s² (~100 deg/s²), sonar range 5 m with a 30° cone.
* The captured session ``drive-tcponly.poses.txt`` (serverDemo driving a
  simulated P3-DX): speed changes by 30 mm/s every 100 ms both up and down
  (300 mm/s²), ``ratioDrive(50, 0, 100)`` goes past 500 mm/s, and
  ``ratioDrive(0, 20, 100)`` turns at 10 deg/s.
* ARIA's ``ArActionRatioInput`` defaults: full throttle forwards = the robot's
  TransVelMax, backwards = a quarter of it, rotation 50 deg/s when stopped and
  25 deg/s at full speed, dead zones 10 % (translation) and 5 % (rotation).
* Braking — what ``stop`` and zero ratios do (checked against ARIA's sources and MobileSim 0.9.8):
  ``p3dx.p`` leaves ``TransDecel`` and ``RotDecel`` at 0, which ``ArRobot`` reads as "keep the
  firmware's own" (it applies a parameter only above 1); the Pioneer firmware's defaults, which
  MobileSim's Pioneer emulation also starts from, are TransDecel 300 mm/s² and RotDecel 100 deg/s²
  (ARIA caps them at 1000 mm/s² and 100 deg/s² when no config packet comes). ``stop`` activates
  ArServerModeStop, whose ``ArRobot::stop()`` sends VEL 0 and RVEL 0 — the firmware slows at that
  TransDecel exactly as it does for zero ``ratioDrive`` ratios (ArActionRatioInput asking for 0);
  only the firmware's ESTOP command brakes harder, and no network client can send it. The capture
  agrees: after ratioDrive(0, 20) and after ``stop`` the speed falls by 30 mm/s every 100 ms. So
  a P3-DX let go at 1.5 m/s rolls 1500²/(2·300) = 3.75 m, plus what it covers before the stop
  arrives: the simulator's StopMode and RatioDriveMode both brake at :data:`TRANS_DECEL`.
"""

from __future__ import annotations

from dataclasses import dataclass

from rtmu.protocol.payloads import drive as protocol_drive

ROBOT_TYPE = "Pioneer"
ROBOT_SUBTYPE = "p3dx"

RADIUS_MM = 250.0
WIDTH_MM = 425
LENGTH_MM = 511
LENGTH_FRONT_MM = 210
LENGTH_REAR_MM = 301

ABSOLUTE_MAX_VEL = 2200.0
ABSOLUTE_MAX_ROT_VEL = 500.0

TRANS_VEL_MAX = 1500.0
"""mm/s the robot reports as TransVelMax (MobileSim's Pioneer default speed; the capture rules out 1000)."""
ROT_VEL_MAX = 100.0
"""deg/s (MobileSim's Pioneer rotational limit, 1.74 rad/s)."""
TRANS_ACCEL = 300.0
TRANS_DECEL = 300.0
ROT_ACCEL = 100.0
ROT_DECEL = 100.0
STOP_DECEL = 1000.0
"""mm/s² of an emergency stop (a collision, a watchdog stop): much harder than a normal slow-down;
ARIA's AbsoluteMaxTransDecel without a config packet."""

# ArActionRatioInput defaults
RATIO_ROT_AT_STOPPED = 50.0
RATIO_ROT_AT_FULL = 25.0
RATIO_TRANS_DEAD_ZONE = protocol_drive.RATIO_TRANS_DEAD_ZONE
RATIO_ROT_DEAD_ZONE = protocol_drive.RATIO_ROT_DEAD_ZONE

# ArActionDriveDistance / jog defaults (used by moveDist)
JOG_SPEED = 400.0
JOG_DECEL = 200.0

SONAR_MAX_RANGE_MM = 5000.0
SONAR_MIN_RANGE_MM = 100.0


@dataclass(frozen=True, slots=True)
class SonarDisc:
    x: float
    y: float
    heading: float


SONAR_DISCS: tuple[SonarDisc, ...] = (
    SonarDisc(69, 136, 90),
    SonarDisc(114, 119, 50),
    SonarDisc(148, 78, 30),
    SonarDisc(166, 27, 10),
    SonarDisc(166, -27, -10),
    SonarDisc(148, -78, -30),
    SonarDisc(114, -119, -50),
    SonarDisc(69, -136, -90),
    SonarDisc(-157, -136, -90),
    SonarDisc(-203, -119, -130),
    SonarDisc(-237, -78, -150),
    SonarDisc(-255, -27, -170),
    SonarDisc(-255, 27, 170),
    SonarDisc(-237, 78, 150),
    SonarDisc(-203, 119, 130),
    SonarDisc(-157, 136, 90),
)
"""ARIA's p3dx SonarUnit table, in order 0..15 (x forward, y left, mm; heading degrees CCW)."""

# Battery (volts). ARIA's defaults: low 11.5, shutdown 11; a charged lead-acid pack reads about 12.8.
BATTERY_FULL_V = 12.8
BATTERY_LOW_V = 11.5
BATTERY_SHUTDOWN_V = 11.0
BATTERY_IDLE_DRAIN_V_PER_S = 1.3 / 7200.0
"""A charged pack falls to the low threshold in about two hours standing still."""
BATTERY_MOTION_DRAIN_V_PER_M = 0.0015
"""Extra drain per metre driven (about 1.3 V over 900 m)."""
BATTERY_TURN_DRAIN_V_PER_REV = 0.0005
