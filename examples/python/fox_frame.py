#!/usr/bin/env python3
"""One frame of the walking Fox stylized with the StyLit painting, all in memory: guide passes
from emaki's renderer (emaki.render), the painting's passes from the reference sphere fitted to
it (emaki.template, examples/stylit_fit.txt), then guided synthesis with the `base` layer's
guides (normal + diffuse) and the Fox's coverage as the mask.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/python/fox_frame.py [FRAME] [OUT.png]
"""

import sys

import numpy as np

import emaki

frame = int(sys.argv[1]) if len(sys.argv) > 1 else 8
out = sys.argv[2] if len(sys.argv) > 2 else "fox_%04d.png" % frame

painting = emaki.read_image("examples/stylit/source_style.png")
h, w = painting.shape[:2]
reference = emaki.template((w, h), sphere=(608.2, 494.2, 242.5), elevation=20, fov=30,
                           light=(0.3, 0.9, -0.3), softness=8)
passes = emaki.render("examples/data/Fox.glb", frame, (960, 540), frames=(0, 47), clip="Walk",
                      loop=True, azimuth=35, elevation=14, light=(0.3, 0.9, -0.3), softness=8)
guides = [(reference["normal"], passes["normal"], 1.0),
          (reference["diffuse"], passes["diffuse"], 1.5)]
try:
    result = emaki.synthesize(painting, guides, mask=passes["alpha"])
except emaki.InputError as e:  # names the argument, e.g. "guides[1][1]: ..."
    sys.exit("emaki: %s" % e)
emaki.write_image(out, result)  # RGBA: the stylized Fox over transparency
print("wrote %s (%s; Fox and ground cover %.0f %% of the frame)"
      % (out, result.shape, 100 * np.mean(passes["alpha"] > 0)))
