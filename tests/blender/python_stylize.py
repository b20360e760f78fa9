# Run inside Blender on the test scene (by python_stylize.sh): registers the add-on, sets the
# painting, its passes and the module folder, stylizes frame 2 with the panel's operator and
# checks the image it made.
#   blender -b scene.blend -P python_stylize.py -- TOOLS_BLENDER_DIR MODULE_DIR WORK
import os
import sys

import bpy

tools, module_dir, work = sys.argv[sys.argv.index("--") + 1:][:3]
sys.dont_write_bytecode = True
sys.path.insert(0, tools)
import emaki_passes  # noqa: E402

emaki_passes.register()
scene = bpy.context.scene
scene.frame_set(2)
scene.emaki_out = os.path.join(work, "frames")
scene.emaki_samples = 8
scene.emaki_painting = os.path.join(work, "painting.png")
scene.emaki_painting_passes = os.path.join(work, "reference", "reference.exr")
scene.emaki_python = module_dir

# A missing painting is one error line, no image.
scene.emaki_painting = os.path.join(work, "missing.png")
try:
    bpy.ops.emaki.stylize_frame()
    raise AssertionError("a missing painting was accepted")
except RuntimeError as e:
    assert "Painting: no file" in str(e), e
assert "emaki frame 0002" not in bpy.data.images
scene.emaki_painting = os.path.join(work, "painting.png")

assert bpy.ops.emaki.stylize_frame() == {"FINISHED"}
import emaki  # noqa: E402  (imported by the operator, in this process)
import numpy as np  # noqa: E402

assert "emaki" in sys.modules and sys.modules["emaki"].__file__.startswith(module_dir)
image = bpy.data.images["emaki frame 0002"]
w, h = image.size
assert (w, h) == (scene.render.resolution_x, scene.render.resolution_y), (w, h)
pixels = np.empty(w * h * 4, np.float32)
image.pixels.foreach_get(pixels)
pixels = pixels.reshape(h, w, 4)[::-1]  # top row first

# The same synthesis, here, from the files the operator used.
frame = os.path.join(work, "frames", "frame_0002.exr")
from emaki_stylize import stylize  # noqa: E402
expected = stylize(emaki, scene.emaki_painting, scene.emaki_painting_passes, frame)
assert expected.shape == (h, w, 4), expected.shape
as_bytes = np.floor(np.clip(expected, 0, 1) * 255 + 0.5) / 255
worst = float(np.abs(pixels - as_bytes).max())
assert worst <= 1.0 / 255 + 1e-6, worst
coverage = emaki.read_image(frame, channels=["alpha.A"] if "alpha.A" in emaki.image_channels(frame)
                            else ["alpha.V"])
assert np.abs(pixels[:, :, 3] - np.clip(coverage, 0, 1)).max() <= 1.0 / 255 + 1e-6
covered = coverage > 0.5
assert covered.mean() > 0.05, covered.mean()
# The stylized objects carry the painting's colours, not a flat fill.
assert pixels[covered, :3].std(axis=0).min() > 0.01, pixels[covered, :3].std(axis=0)
print("python_stylize: frame 2 (%dx%d) stylized in Blender; %.0f %% covered; max difference "
      "from emaki.synthesize %.4f" % (w, h, 100 * covered.mean(), worst))
