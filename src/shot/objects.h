// A shot's source.objects opened: each asset file loaded once, each object's clip found and
// checked against the shot's frames, all placed into one scene (scene/assembly.h). Errors name
// source.objects[N].KEY. Internal to the shot module.
#pragma once

#include "pipeline/shot_description.h"
#include "scene/scene.h"

namespace emaki::shot {

scene::Scene load_objects(const pipeline::Source& source);

}  // namespace emaki::shot
