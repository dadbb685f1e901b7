#!/usr/bin/env python3
"""Segments the bundled sample with bims's Python module and plots one
frame's image beside its moving mask (docs/python.md).

    PYTHONPATH=build/python python3 examples/python/segment_sample.py [OUT.png]
"""

import sys

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt
import numpy as np

import bims

cfg = bims.Config.from_file("config/default.ini")
pipe = bims.Pipeline(cfg)
shown = 60  # the frame to plot
for f in bims.read_rawlog("rawlogs/pendulum_slow.rawlog"):
    r = pipe.process(f.depth, rgb=f.rgb, stamp=f.stamp, imu=f.imu)
    if r.index == shown:
        rgb, depth, mask, pose = f.rgb, np.asarray(f.depth), r.mask, r.pose
print(f"{pipe.frames_processed} frames; frame {shown}: "
      f"{np.count_nonzero(mask)} moving pixels, camera at {pose[:3, 3].round(3)} m")

fig, ax = plt.subplots(1, 3, figsize=(12, 3.4))
ax[0].imshow(rgb)
ax[0].set_title(f"frame {shown}: image")
ax[1].imshow(depth * float(f.depth.units), cmap="viridis")
ax[1].set_title("depth [m]")
overlay = rgb.copy()
overlay[mask > 0] = (0.4 * overlay[mask > 0] + [153, 0, 0]).astype(np.uint8)
ax[2].imshow(overlay)
ax[2].set_title("moving (r.mask, red)")
for a in ax:
    a.axis("off")
fig.tight_layout()
out = sys.argv[1] if len(sys.argv) > 1 else "python_mask.png"
fig.savefig(out, dpi=80)
print("wrote", out)
