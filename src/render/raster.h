// The triangle rasteriser behind every pass: a visibility buffer (nearest triangle and its
// perspective-correct barycentrics per sample) filled by tiles in parallel. Vertices are
// snapped to 1/256 of a sample and edges tested in exact integer arithmetic with a tie rule,
// so triangles sharing an edge cover every sample exactly once (no cracks, no double hits).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

namespace emaki::render {

// A vertex after projection. Screen position = (x / w, y / w) in NDC (x right, y up);
// `depth` is the view-space distance used for near-plane clipping; `key` is interpolated
// linearly in screen space and decides visibility (larger = nearer): 1 / depth for
// perspective cameras, -depth for orthographic ones.
struct ClipVertex {
  float x = 0, y = 0, w = 1;
  float depth = 0;
};

struct VisibilityBuffer {
  int width = 0, height = 0;  // in samples
  std::vector<float> key;     // -inf where nothing was drawn
  std::vector<int32_t> tri;   // triangle index, -1 where nothing was drawn
  std::vector<float> b1, b2;  // barycentrics of vertices 1 and 2 of `tri` (perspective-correct)
  void reset(int w, int h, bool with_attributes);
  std::size_t index(int x, int y) const { return std::size_t(y) * width + x; }
};

struct RasterOptions {
  bool perspective = true;
  float znear = 0.01f;          // triangles are clipped to depth >= znear
  bool with_attributes = true;  // false: depth (key) only, e.g. a shadow map
};

// Draws triangles (3 vertex indices each) into `out`, whose size says the sample grid; NDC
// [-1, 1] maps to the whole grid. Results do not depend on the thread count: each tile is drawn
// by one task and triangles are visited in index order (ties keep the earlier triangle).
void rasterize(const std::vector<ClipVertex>& vertices, const std::vector<uint32_t>& indices,
               const RasterOptions& options, VisibilityBuffer& out);

}  // namespace emaki::render
