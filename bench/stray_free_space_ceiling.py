#!/usr/bin/env python3
"""How much of a capture's moving label any causal free-space method can find.

A voxel-grid method like bims's tier 1 flags a reading as moving when the
space it lies in was seen free before. This script asks the labels and the
reference poses, not bims: for every pixel that masks_proxy/ labels moving
(255) and that has a depth reading, it back-projects the reading with ARKit's
pose and checks every other frame of the capture: was the point seen *free*
there (in view, with a depth reading more than MARGIN beyond it)? It prints
the share of moving-labelled pixels seen free in an earlier frame (what an
online method can know), only in a later one (what only hindsight knows),
and never (what no free-space evidence supports). Not part of CTest; needs
python3-numpy and python3-opencv (Debian); ~1 minute.

    bench/stray_free_space_ceiling.py [CAPTURE] [--margin M] [--min-confidence C]
                                      [--colour-width W]

CAPTURE defaults to ../shared/data/stray_early (a Stray Scanner folder with
odometry.csv, camera_matrix.csv, depth/, confidence/ and masks_proxy/).
"""
import argparse
import os
import sys

try:
    import cv2
    import numpy as np
except ImportError as e:
    sys.exit(f"stray_free_space_ceiling.py: {e.name} missing "
             "(apt-get install python3-numpy python3-opencv)")


def quat_to_R(x, y, z, w):
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("capture", nargs="?",
                    default=os.path.join(here, "..", "..", "shared", "data",
                                         "stray_early"))
    ap.add_argument("--margin", type=float, default=0.10,
                    help="seen free: a reading this far beyond the point [m]")
    ap.add_argument("--colour-width", type=float, default=1920,
                    help="width of the colour stream camera_matrix.csv describes")
    ap.add_argument("--min-confidence", type=int, default=1,
                    help="ARKit confidence a depth reading needs (0-2)")
    a = ap.parse_args()
    cap = a.capture
    for need in ("odometry.csv", "camera_matrix.csv", "depth", "masks_proxy"):
        if not os.path.exists(os.path.join(cap, need)):
            sys.exit(f"stray_free_space_ceiling.py: {cap}: no {need}")
    od = np.genfromtxt(os.path.join(cap, "odometry.csv"), delimiter=",",
                       skip_header=1)
    if od.ndim != 2 or od.shape[1] < 9:
        sys.exit(f"stray_free_space_ceiling.py: {cap}/odometry.csv: "
                 "expected 9 columns")
    stamps = od[:, 0]
    R = [quat_to_R(*r[5:9]) for r in od]
    t = od[:, 2:5]
    first = int(np.argmax(np.any(t != 0, axis=1)))  # ARKit's position starts
    depth0 = cv2.imread(os.path.join(cap, "depth", "000000.png"), -1)
    H, W = depth0.shape
    Kc = np.genfromtxt(os.path.join(cap, "camera_matrix.csv"), delimiter=",")
    # camera_matrix.csv describes the colour stream: scaled to the depth
    # grid as bims-import-stray does (config/stray.ini's colour_width)
    s = W / a.colour_width
    K = np.array([[Kc[0, 0] * s, 0, Kc[0, 2] * s], [0, Kc[1, 1] * s, Kc[1, 2] * s],
                  [0, 0, 1]])
    Kinv = np.linalg.inv(K)
    cache = {}

    def depth(k):
        if k not in cache:
            d = cv2.imread(os.path.join(cap, "depth", f"{k:06d}.png"),
                           -1).astype(np.float32) / 1000
            cpath = os.path.join(cap, "confidence", f"{k:06d}.png")
            if os.path.exists(cpath):
                d[cv2.imread(cpath, -1) < a.min_confidence] = 0
            cache[k] = d
        return cache[k]

    labels = {os.path.splitext(f)[0]: f
              for f in os.listdir(os.path.join(cap, "masks_proxy"))}
    n = len(stamps)
    total = past = later = 0
    frames = 0
    for k in range(first, n):
        key = min(labels, key=lambda x: abs(float(x) - stamps[k]))
        if abs(float(key) - stamps[k]) > 1e-3:
            continue
        gt = cv2.imread(os.path.join(cap, "masks_proxy", labels[key]), 0)
        d = depth(k)
        v, u = np.nonzero((gt == 255) & (d > 0))
        if len(u) == 0:
            continue
        frames += 1
        z = d[v, u]
        Xw = R[k] @ (Kinv @ np.vstack([u, v, np.ones_like(u)]) * z) + t[k][:, None]
        seen_past = np.zeros(len(u), bool)
        seen_later = np.zeros(len(u), bool)
        for j in range(first, n):
            if j == k:
                continue
            Xj = R[j].T @ (Xw - t[j][:, None])
            zz = Xj[2]
            ok = zz > 0.05
            zs = np.where(ok, zz, 1)
            uu = np.round(K[0, 0] * Xj[0] / zs + K[0, 2]).astype(int)
            vv = np.round(K[1, 1] * Xj[1] / zs + K[1, 2]).astype(int)
            ok &= (uu >= 0) & (uu < W) & (vv >= 0) & (vv < H)
            dj = np.zeros(len(u))
            dj[ok] = depth(j)[vv[ok], uu[ok]]
            free = ok & (dj > zz + a.margin)
            if j < k:
                seen_past |= free
            else:
                seen_later |= free
        total += len(u)
        past += seen_past.sum()
        later += (seen_later & ~seen_past).sum()
    if total == 0:
        sys.exit("stray_free_space_ceiling.py: no moving-labelled pixel with depth")
    print(f"{os.path.relpath(cap)}: {total} moving-labelled pixels with depth in {frames} frames "
          f"(margin {a.margin} m, confidence >= {a.min_confidence})")
    print(f"seen free in an earlier frame: {past / total:.3f}")
    print(f"seen free only in a later frame: {later / total:.3f}")
    print(f"never seen free: {1 - (past + later) / total:.3f}")


if __name__ == "__main__":
    main()
