// The parts of the shot file parser (parser.cpp reads the top level and calls these). Internal
// to the shot module.
#pragma once

#include <string>

#include "pipeline/shot_description.h"
#include "shot/toml_reader.h"

namespace emaki::shot {

// [source]: a glTF scene, objects assembled from glTF assets, or a studio render's EXR sequence
// (whose first frame is opened to check its channels and take its size).
void parse_source(const Reader& r, const PathContext& ctx, pipeline::Source& s);

// Objects an assembled scene may hold (source.objects).
inline constexpr std::size_t kMaxObjects = 256;

// source.objects (r is [source]): the assets' files must exist; ids are unique. Sets the
// source's clip to the assembly's.
void parse_objects(const Reader& r, const PathContext& ctx, pipeline::Source& s);

// [exemplars.NAME]
void parse_exemplar(const Reader& r, const PathContext& ctx, pipeline::Exemplar& e);

// [layers.NAME]; its exemplar must be one of shot.exemplars.
void parse_layer(const Reader& r, const pipeline::Shot& shot, pipeline::Layer& l);

}  // namespace emaki::shot
