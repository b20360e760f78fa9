// composite_frame: a frame's layers over the paper, the paper made once per shot.
#include <mutex>
#include <tuple>

#include "colour/colour.h"
#include "composite/composite.h"
#include "core/check.h"
#include "pipeline/run.h"
#include "render/passes.h"

namespace emaki::pipeline {

// What the paper was made from, and the paper.
struct MadePaper {
  using Key =
      std::tuple<int, int, float, float, float, float, CompositingSpace, const colour::Config*>;
  std::mutex mutex;
  Key key;
  std::shared_ptr<const Image<float>> image;
};

std::shared_ptr<MadePaper> new_made_paper() {
  return std::make_shared<MadePaper>();
}

namespace {

// The paper of `shot` at width x height in its working space, from `made` when it was made from
// the same keys (the texture is the one CompositeInputs holds).
std::shared_ptr<const Image<float>> made_paper(MadePaper& made, const Shot& shot,
                                               const composite::Paper& paper, int width, int height,
                                               const composite::ToWorkingSpace& to_working) {
  const MadePaper::Key key{width,
                           height,
                           paper.scale,
                           paper.color.r,
                           paper.color.g,
                           paper.color.b,
                           shot.compositing.space,
                           &shot.colour.get()};
  const std::lock_guard<std::mutex> lock(made.mutex);
  if (made.image && made.key == key) return made.image;
  auto image = std::make_shared<Image<float>>(composite::paper_image(paper, width, height));
  if (to_working) to_working(image->view());
  made.key = key;
  made.image = image;
  return image;
}

}  // namespace

Image<float> composite_frame(const Shot& shot, ImageView<const float> passes,
                             const std::vector<ImageView<const float>>& layers,
                             const CompositeInputs& ci) {
  CHECK_EQ(layers.size(), shot.layers.size());
  const Image<float> albedo = extract(passes, render::kAlbedo, 3);
  std::vector<composite::LayerInput> inputs;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    composite::LayerInput in;
    in.name = shot.layers[i].name;
    in.value = layers[i];
    in.value_channels = shot.layers[i].single_colour ? 1 : 3;
    in.albedo = albedo.cview();
    in.look = shot.layers[i].look;
    inputs.push_back(in);
  }
  composite::Paper paper;
  paper.texture = ci.paper.empty() ? ImageView<const float>{} : ci.paper.cview();
  paper.scale = shot.compositing.paper_scale;
  paper.color = shot.compositing.paper_color;
  composite::ToWorkingSpace to_working;
  if (shot.compositing.space != CompositingSpace::kDisplay) {
    const colour::Config& config = shot.colour.get();
    to_working = [&config](ImageView<float> rgb) {
      config.convert(rgb, "color_picking", "scene_linear");
    };
  }
  // paper_image throws for a scale <= 0: left to composite() (a shot's keys are checked).
  std::shared_ptr<const Image<float>> made;
  if (ci.made_paper && paper.scale > 0.0f) {
    made = made_paper(*ci.made_paper, shot, paper, passes.width, passes.height, to_working);
    paper.made = made->cview();
  }
  return composite::composite(inputs, paper, passes.width, passes.height, to_working);
}

}  // namespace emaki::pipeline
