// The figures of the Blender tests (tests/blender/*.sh):
//
//   blender_check compare A.exr[:PRESET] B.exr[:PRESET] [--max-normal-deg D] [--max-position F]
//                 [--min-iou F] [--max-motion PX]
//     Two pass files of the same frame (PRESET "emaki", the default, or "blender"): coverage IoU
//     (alpha > 0.5), mean normal angle and mean position error over the pixels both cover fully
//     (position as a fraction of the side of A's normalisation cube, and the mean difference of
//     position_norm), depth and albedo differences. Exits 1 when a limit is exceeded.
//
//   blender_check passes FILE[:PRESET]...   (ranges of each pass; see passes() below)
//
//   blender_check outputs OUT_DIR FIRST LAST LAYER...
//     A finished `emaki run`: each frame's layered EXR holds every pass, each layer and the
//     composite; values are finite and in [0, 1]; each layer's coverage matches the alpha pass
//     where the layer's mask is the covered pixels (layers named base*). Exits 1 otherwise.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/image_io.h"
#include "render/passes.h"
#include "store/frame_sequence.h"

namespace {

using emaki::Image;
namespace render = emaki::render;

Image<float> load(const std::string& arg) {
  const std::size_t colon = arg.rfind(':');
  if (colon != std::string::npos && colon > 0 && arg.find('/', colon) == std::string::npos)
    return emaki::io::read_pass_file(arg.substr(0, colon),
                                     arg.substr(colon + 1) == "blender"
                                         ? emaki::pipeline::SourcePreset::kBlender
                                         : emaki::pipeline::SourcePreset::kEmaki);
  return emaki::io::read_pass_file(arg);
}

// compare's pass limits (--max-normal-deg, --max-position, --min-iou, --max-motion).
struct Limits {
  double max_normal = INFINITY, max_position = INFINITY, min_iou = 0.0, max_motion = INFINITY;
};

Limits parse_limits(int argc, char** argv) {
  Limits l;
  for (int i = 4; i + 1 < argc; i += 2) {
    const std::string opt = argv[i];
    const double v = std::atof(argv[i + 1]);
    if (opt == "--max-normal-deg")
      l.max_normal = v;
    else if (opt == "--max-position")
      l.max_position = v;
    else if (opt == "--min-iou")
      l.min_iou = v;
    else if (opt == "--max-motion")
      l.max_motion = v;
    else
      throw emaki::Error(opt, "unknown option");
  }
  return l;
}

// Sums of per-pixel differences between two pass files.
struct PassDiff {
  long both = 0, either = 0, full = 0, line_both = 0, line_either = 0;
  double normal_deg = 0.0, position = 0.0, position_norm = 0.0, depth = 0.0, albedo = 0.0;
  double motion = 0.0, rest = 0.0, diffuse = 0.0, shadow = 0.0;

  void add_coverage(const float* pa, const float* pb) {
    const bool ca = pa[render::kAlpha] > 0.5f, cb = pb[render::kAlpha] > 0.5f;
    both += ca && cb;
    either += ca || cb;
    const bool line_a = pa[render::kOutline] > 0.5f, line_b = pb[render::kOutline] > 0.5f;
    line_both += line_a && line_b;
    line_either += line_a || line_b;
  }
  // A pixel fully covered in both.
  void add_full(const float* pa, const float* pb) {
    ++full;
    double dot = 0.0, la = 0.0, lb = 0.0, dp = 0.0, dn = 0.0, dc = 0.0, dr = 0.0;
    auto sq = [](double v) { return v * v; };
    for (int c = 0; c < 3; ++c) {
      dot += double(pa[render::kNormal + c]) * pb[render::kNormal + c];
      la += sq(pa[render::kNormal + c]);
      lb += sq(pb[render::kNormal + c]);
      dp += sq(double(pa[render::kPosition + c]) - pb[render::kPosition + c]);
      dn += sq(double(pa[render::kPositionNorm + c]) - pb[render::kPositionNorm + c]);
      dc += std::abs(double(pa[render::kAlbedo + c]) - pb[render::kAlbedo + c]) / 3.0;
      dr += sq(double(pa[render::kRestPosition + c]) - pb[render::kRestPosition + c]);
    }
    motion += std::hypot(double(pa[render::kMotion]) - pb[render::kMotion],
                         double(pa[render::kMotion + 1]) - pb[render::kMotion + 1]);
    rest += std::sqrt(dr);
    diffuse += std::abs(double(pa[render::kDiffuse]) - pb[render::kDiffuse]);
    shadow += std::abs(double(pa[render::kShadow]) - pb[render::kShadow]);
    normal_deg += std::acos(std::clamp(dot / std::sqrt(la * lb + 1e-30), -1.0, 1.0)) * 180.0 /
                  std::numbers::pi;
    position += std::sqrt(dp);
    position_norm += std::sqrt(dn);
    depth += std::abs(double(pa[render::kDepth]) - pb[render::kDepth]) /
             std::max(1e-6, double(pa[render::kDepth]));
    albedo += dc;
  }
};

// A's position cube side (position = lo + side * position_norm), from pixels far apart from a
// reference pixel p0: |p - q| = side * |pn - qn|.
double cube_side(const Image<float>& a, const float* p0) {
  double num = 0.0, den = 0.0;
  for (int y = 0; y < a.height(); y += 3)
    for (int x = 0; x < a.width(); x += 3) {
      const float* pa = a.at(x, y);
      if (pa[render::kAlpha] < 0.999f || !p0) continue;
      for (int c = 0; c < 3; ++c) {
        num += std::abs(double(pa[render::kPosition + c]) - p0[render::kPosition + c]);
        den += std::abs(double(pa[render::kPositionNorm + c]) - p0[render::kPositionNorm + c]);
      }
    }
  return den > 0.0 ? num / den : 1.0;
}

int compare(int argc, char** argv) {
  if (argc < 4) throw emaki::Error("compare", "needs two pass files");
  const Limits lim = parse_limits(argc, argv);
  const Image<float> a = load(argv[2]), b = load(argv[3]);
  if (a.width() != b.width() || a.height() != b.height())
    throw emaki::Error(argv[3], fmt::format("is {}x{}, {} is {}x{}", b.width(), b.height(), argv[2],
                                            a.width(), a.height()));
  PassDiff d;
  const float* p0 = nullptr;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      const float *pa = a.at(x, y), *pb = b.at(x, y);
      d.add_coverage(pa, pb);
      if (pa[render::kAlpha] < 0.999f || pb[render::kAlpha] < 0.999f) continue;
      if (!p0 && std::abs(pa[render::kPositionNorm] - 0.5f) > 0.1f) p0 = pa;
      d.add_full(pa, pb);
    }
  if (d.full == 0) throw emaki::Error(argv[2], "no pixel is fully covered in both files");
  const double side = cube_side(a, p0);
  const long full = d.full;
  const double iou = d.either ? double(d.both) / double(d.either) : 1.0;
  const double normal_deg = d.normal_deg / full, pos_frac = d.position / full / side;
  std::printf(
      "pixels covered: both %ld, either %ld; coverage IoU %.4f; over %ld fully covered pixels: "
      "normal mean angle %.3f deg, position mean error %.5f of the box (box side %.4g), "
      "position_norm mean difference %.5f, depth mean relative error %.5f, albedo mean "
      "difference %.4f, motion mean difference %.3f px, rest_position mean difference %.4f, "
      "diffuse mean difference %.4f, shadow mean difference %.4f; outline IoU %.3f\n",
      d.both, d.either, iou, full, normal_deg, pos_frac, side, d.position_norm / full,
      d.depth / full, d.albedo / full, d.motion / full, d.rest / full, d.diffuse / full,
      d.shadow / full, d.line_either ? double(d.line_both) / d.line_either : 1.0);
  bool ok = true;
  if (normal_deg > lim.max_normal)
    std::printf("FAIL: normal angle %.3f > %.3f deg\n", normal_deg, lim.max_normal), ok = false;
  if (pos_frac > lim.max_position)
    std::printf("FAIL: position error %.5f > %.5f of the box\n", pos_frac, lim.max_position),
        ok = false;
  if (d.motion / full > lim.max_motion)
    std::printf("FAIL: motion %.3f > %.3f px\n", d.motion / full, lim.max_motion), ok = false;
  if (iou < lim.min_iou)
    std::printf("FAIL: coverage IoU %.4f < %.4f\n", iou, lim.min_iou), ok = false;
  return ok ? 0 : 1;
}

int outputs(int argc, char** argv) {
  if (argc < 6) throw emaki::Error("outputs", "needs OUT_DIR FIRST LAST LAYER...");
  const std::string dir = argv[2];
  const int first = std::atoi(argv[3]), last = std::atoi(argv[4]);
  bool ok = true;
  for (int f = first; f <= last; ++f) {
    const std::string layered = fmt::format("{}/layered/frame_{:04d}.exr", dir, f);
    const std::string png = fmt::format("{}/composite/frame_{:04d}.png", dir, f);
    if (!std::filesystem::is_regular_file(png))
      std::printf("FAIL: no composite %s\n", png.c_str()), ok = false;
    const std::vector<std::string> have = emaki::io::list_channels(layered);
    std::vector<std::string> want = render::channel_names();
    for (const char* c : {"composite.R", "composite.G", "composite.B"}) want.push_back(c);
    for (int i = 5; i < argc; ++i) {
      want.push_back(fmt::format("layer_{}.Y", argv[i]));
      want.push_back(fmt::format("layer_{}.A", argv[i]));
    }
    for (const std::string& w : want)
      if (std::find(have.begin(), have.end(), w) == have.end())
        std::printf("FAIL: %s has no channel %s\n", layered.c_str(), w.c_str()), ok = false;
    if (!ok) continue;
    const Image<float> img = emaki::io::read_image_float(layered, {want});
    const int n_pass = render::kChannelCount;
    long bad = 0, mismatch = 0, covered = 0, pixels = 0;
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x) {
        const float* p = img.at(x, y);
        ++pixels;
        for (int c = n_pass; c < img.channels(); ++c)
          if (!std::isfinite(p[c]) || p[c] < -1e-3f || p[c] > 1.001f) ++bad;
        for (int c = 0; c < n_pass; ++c)
          if (!std::isfinite(p[c])) ++bad;
        const bool cov = p[render::kAlpha] > 0.5f && p[render::kObjectId] >= 1.0f;
        covered += cov;
        for (int i = 5; i < argc; ++i) {
          if (std::strncmp(argv[i], "base", 4) != 0) continue;
          const float la = p[n_pass + 3 + 2 * (i - 5) + 1];
          if ((la > 0.5f) != cov) ++mismatch;
        }
      }
    std::printf(
        "frame %d: %ldx%ld px, %ld covered (%.1f %%), %ld values out of range, %ld "
        "pixels where a base layer's alpha disagrees with coverage\n",
        f, long(img.width()), long(img.height()), covered, 100.0 * covered / pixels, bad, mismatch);
    if (bad > 0 || mismatch > pixels / 100 || covered == 0) ok = false;
  }
  if (!ok) std::printf("FAIL\n");
  return ok ? 0 : 1;
}

// blender_check passes FILE[:PRESET]...: each file's passes hold emaki's ranges: alpha, diffuse,
// shadow and outline in [0, 1], unit normals facing the camera, positive depth, integer ids,
// objects' position_norm and rest_position in [0, 1], where covered. Exits 1 otherwise.
int passes(int argc, char** argv) {
  bool ok = true;
  for (int i = 2; i < argc; ++i) {
    const Image<float> img = load(argv[i]);
    long covered = 0, bad = 0;
    std::string first_bad;
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x) {
        const float* p = img.at(x, y);
        auto check = [&](bool good, const char* what) {
          if (good) return;
          if (bad++ == 0) first_bad = fmt::format("{} at ({}, {})", what, x, y);
        };
        for (int c : {render::kAlpha, render::kDiffuse, render::kShadow, render::kOutline})
          check(p[c] >= 0.0f && p[c] <= 1.0f, "a value outside [0, 1]");
        for (int c : {render::kObjectId, render::kMaterialId})
          check(p[c] == std::round(p[c]) && p[c] >= 0.0f, "an id that is no integer");
        if (p[render::kAlpha] < 0.999f) continue;
        ++covered;
        // Inside one object only: an edge pixel averages two surfaces under one id.
        bool inside = x > 0 && y > 0 && x + 1 < img.width() && y + 1 < img.height();
        for (int d = 0; inside && d < 4; ++d) {
          const float* q = img.at(x + (d == 0) - (d == 1), y + (d == 2) - (d == 3));
          inside = q[render::kObjectId] == p[render::kObjectId] && q[render::kAlpha] >= 0.999f;
        }
        if (!inside) continue;
        const float len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        check(std::abs(len - 1.0f) < 0.05f, "a normal that is not unit length");
        check(p[render::kNormal + 2] > -0.3f, "a normal facing away from the camera");
        check(p[render::kDepth] > 0.0f, "depth <= 0 on a covered pixel");
        if (p[render::kObjectId] >= 2.0f)
          for (int c = 0; c < 3; ++c) {
            check(p[render::kPositionNorm + c] > -0.01f && p[render::kPositionNorm + c] < 1.01f,
                  "an object's position_norm outside [0, 1]");
            check(p[render::kRestPosition + c] > -0.01f && p[render::kRestPosition + c] < 1.01f,
                  "an object's rest_position outside [0, 1]");
          }
      }
    std::printf("%s: %ld fully covered pixels, %ld values out of range%s%s\n", argv[i], covered,
                bad, bad ? ", first: " : "", first_bad.c_str());
    // A few back-facing or averaged edge normals are allowed; nothing else.
    if (covered == 0 || bad > covered / 200) ok = false;
  }
  if (!ok) std::printf("FAIL\n");
  return ok ? 0 : 1;
}

// blender_check pixel X Y FILE[:PRESET]...: every pass value of one pixel (for debugging).
int pixel(int argc, char** argv) {
  const int x = std::atoi(argv[2]), y = std::atoi(argv[3]);
  for (int i = 4; i < argc; ++i) {
    const Image<float> img = load(argv[i]);
    std::printf("%s:", argv[i]);
    for (int c = 0; c < img.channels(); ++c) std::printf(" %.4g", img(x, y, c));
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc >= 2 && std::string(argv[1]) == "compare") return compare(argc, argv);
    if (argc >= 2 && std::string(argv[1]) == "outputs") return outputs(argc, argv);
    if (argc >= 5 && std::string(argv[1]) == "pixel") return pixel(argc, argv);
    if (argc >= 3 && std::string(argv[1]) == "passes") return passes(argc, argv);
    std::fprintf(stderr,
                 "usage: blender_check compare A.exr[:preset] B.exr[:preset] ... | "
                 "outputs OUT_DIR FIRST LAST LAYER...\n");
    return 2;
  } catch (const emaki::Error& e) {
    std::fprintf(stderr, "blender_check: error: %s\n", e.what());
    return 1;
  }
}
