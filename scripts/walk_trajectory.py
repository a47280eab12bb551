#!/usr/bin/env python3
"""A walk through a scene for `render --trajectory` / `xr --offscreen --trajectory`: the head moves
along a line at walking pace, looks left and right and up into the vaults, so that the frame's
cost changes as it would for a visitor. One line per frame (docs: src/pvr/app/trajectory.h).

  walk_trajectory.py --seconds 30 --hz 90 -- FROM_X,FROM_Y,FROM_Z TO_X,TO_Y,TO_Z > walk.traj
"""
import argparse
import math


def quat(yaw, pitch):
    # OpenXR: -Z forward, +Y up; yaw about +Y, then pitch about the head's +X.
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    # q_yaw * q_pitch
    return (cy * sp, sy * cp, -sy * sp, cy * cp)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("start")
    p.add_argument("end")
    p.add_argument("--seconds", type=float, default=30.0)
    p.add_argument("--hz", type=float, default=90.0)
    p.add_argument("--look-left-right", type=float, default=70.0, help="degrees of the side-to-side sweep")
    p.add_argument("--look-up", type=float, default=55.0, help="degrees of the upward glances")
    a = p.parse_args()
    s = [float(v) for v in a.start.split(",")]
    e = [float(v) for v in a.end.split(",")]
    heading = math.atan2(-(e[0] - s[0]), -(e[2] - s[2]))  # yaw that looks from start to end
    n = int(round(a.seconds * a.hz))
    print(f"# {a.seconds:g} s walk at {a.hz:g} Hz from {a.start} to {a.end} (scripts/walk_trajectory.py)")
    for i in range(n):
        t = i / max(n - 1, 1)
        sec = i / a.hz
        pos = [s[k] + (e[k] - s[k]) * t for k in range(3)]
        pos[1] += 0.02 * math.sin(2 * math.pi * 1.8 * sec)  # steps
        yaw = heading + math.radians(a.look_left_right) * math.sin(2 * math.pi * sec / 9.0)
        # Glances up into the vault around 8 s and 21 s, 2.5 s each.
        up = sum(math.exp(-((sec - c) / 1.2) ** 2) for c in (8.0, 21.0))
        pitch = math.radians(a.look_up) * up
        q = quat(yaw, pitch)
        print(f"{pos[0]:.4f} {pos[1]:.4f} {pos[2]:.4f} {q[0]:.6f} {q[1]:.6f} {q[2]:.6f} {q[3]:.6f} 0.5 0.5")


if __name__ == "__main__":
    main()
