#!/usr/bin/env python3
"""EbSynth's StyLit example through emaki's Python module: the same pixels as

    emaki synth -style source_style.png -guide source_fullgi.png target_fullgi.png -weight 0.5 ...

Run from the repository root after building:
    PYTHONPATH=build/release/python /usr/bin/python3 examples/python/stylit.py [OUT.png]
"""

import sys

import emaki

E = "examples/stylit/"
style = emaki.read_image(E + "source_style.png")  # HxWx3 uint8, read in place by the engine
guides = [(emaki.read_image(E + "source_%s.png" % g), emaki.read_image(E + "target_%s.png" % g), 0.5)
          for g in ("fullgi", "dirdif", "dirspc", "indirb")]
out = emaki.synthesize(style, guides, seed=1, progress=lambda p: print("level %d/%d" % (p["level"] + 1, p["levels"])))
emaki.write_image(sys.argv[1] if len(sys.argv) > 1 else "stylit.png", out)  # uint8 -> 8-bit PNG
print("wrote", sys.argv[1] if len(sys.argv) > 1 else "stylit.png", out.shape, out.dtype)
