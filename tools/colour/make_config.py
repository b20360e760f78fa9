#!/usr/bin/python3
"""Writes src/colour/emaki.ocio, the OpenColorIO config emaki uses when neither $OCIO nor the
shot file's colour.config names one. Run with Debian's python3-pyopencolorio (OCIO 2.1):

    /usr/bin/python3 tools/colour/make_config.py src/colour/emaki.ocio

Every transform is one of OCIO's own (built-in transforms, the sRGB curve as an exponent with
a linear segment), so the file needs no LUT beside it. Its reference space is scene-linear
Rec.709 (D65).
"""
import sys

import PyOpenColorIO as ocio

SCENE_LINEAR = "scene-linear Rec.709"
ACESCG = "ACEScg"
ACES = "ACES2065-1"
SRGB_TEXTURE = "sRGB texture"
RAW = "raw"
FILMIC = "sRGB filmic"


def colour_space(name, family, description, to_reference=None, from_reference=None,
                 is_data=False):
    cs = ocio.ColorSpace(name=name, family=family, description=description,
                         bitDepth=ocio.BIT_DEPTH_F32, isData=is_data)
    if to_reference is not None:
        cs.setTransform(to_reference, ocio.COLORSPACE_DIR_TO_REFERENCE)
    if from_reference is not None:
        cs.setTransform(from_reference, ocio.COLORSPACE_DIR_FROM_REFERENCE)
    return cs


def make_config():
    config = ocio.Config.CreateRaw()
    config.setMajorVersion(2)
    config.setMinorVersion(1)
    config.setName("emaki")
    config.setDescription("emaki's built-in config: scene-linear Rec.709 reference, ACEScg, "
                          "ACES2065-1, "
                          "sRGB texture, raw data; an sRGB display with a Standard and a "
                          "Filmic view. Written by tools/colour/make_config.py.")
    config.setSearchPath("")
    for cs in list(config.getColorSpaceNames()):
        config.removeColorSpace(cs)

    config.addColorSpace(colour_space(
        SCENE_LINEAR, "Linear", "linear light, Rec.709 primaries, D65 white (the reference)"))
    config.addColorSpace(colour_space(
        ACESCG, "Linear", "linear light, ACES AP1 primaries (ACEScg)",
        to_reference=ocio.BuiltinTransform("UTILITY - ACES-AP1_to_LINEAR-REC709_BFD")))
    # The interchange space (the aces_interchange role), through which emaki works out the
    # chromaticities it writes into EXR headers.
    config.addColorSpace(colour_space(
        ACES, "Linear", "linear light, ACES AP0 primaries (ACES2065-1, interchange)",
        to_reference=ocio.GroupTransform([
            ocio.BuiltinTransform("ACEScg_to_ACES2065-1", ocio.TRANSFORM_DIR_INVERSE),
            ocio.BuiltinTransform("UTILITY - ACES-AP1_to_LINEAR-REC709_BFD")])))
    # The sRGB curve (IEC 61966-2-1) on Rec.709 primaries: what paintings and scans hold.
    config.addColorSpace(colour_space(
        SRGB_TEXTURE, "Texture", "sRGB-encoded Rec.709: paintings, paper scans, 8-bit images",
        to_reference=ocio.ExponentWithLinearTransform(gamma=[2.4, 2.4, 2.4, 1.0],
                                                       offset=[0.055, 0.055, 0.055, 0.0])))
    config.addColorSpace(colour_space(
        RAW, "Data", "not colour: normals, positions, ids, motion (never converted)",
        is_data=True))
    # A filmic-like view: the ACES 1.0 SDR video output transform, then the sRGB display curve.
    filmic = ocio.GroupTransform([
        ocio.BuiltinTransform("UTILITY - ACES-AP1_to_LINEAR-REC709_BFD",
                              ocio.TRANSFORM_DIR_INVERSE),
        ocio.BuiltinTransform("ACEScg_to_ACES2065-1"),
        ocio.BuiltinTransform("ACES-OUTPUT - ACES2065-1_to_CIE-XYZ-D65 - SDR-VIDEO_1.0"),
        ocio.BuiltinTransform("DISPLAY - CIE-XYZ-D65_to_sRGB"),
    ])
    config.addColorSpace(colour_space(
        FILMIC, "Display", "the Filmic view's output: ACES 1.0 SDR tone scale, sRGB display",
        from_reference=filmic))

    for role, space in [(ocio.ROLE_REFERENCE, SCENE_LINEAR), (ocio.ROLE_SCENE_LINEAR, SCENE_LINEAR),
                        (ocio.ROLE_DEFAULT, SCENE_LINEAR), (ocio.ROLE_RENDERING, SCENE_LINEAR),
                        (ocio.ROLE_COMPOSITING_LOG, SCENE_LINEAR),
                        (ocio.ROLE_COLOR_PICKING, SRGB_TEXTURE),
                        (ocio.ROLE_TEXTURE_PAINT, SRGB_TEXTURE),
                        (ocio.ROLE_MATTE_PAINT, SRGB_TEXTURE), (ocio.ROLE_DATA, RAW),
                        ("aces_interchange", ACES)]:
        config.setRole(role, space)

    # CreateRaw's own display (sRGB: Raw) goes, so that Standard is the display's first view.
    config.clearDisplays()
    config.addDisplayView("sRGB", "Standard", SRGB_TEXTURE)
    config.addDisplayView("sRGB", "Filmic", FILMIC)
    config.addDisplayView("sRGB", "Raw", RAW)
    config.setActiveDisplays("sRGB")
    config.setActiveViews("Standard, Filmic, Raw")
    config.validate()
    return config


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: make_config.py OUT.ocio")
    text = make_config().serialize()
    with open(sys.argv[1], "w", encoding="utf-8") as f:
        f.write(text)


if __name__ == "__main__":
    main()
