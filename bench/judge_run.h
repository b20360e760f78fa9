// What temporal_bench asks of the independent judge (../shared/tools/judge): its guides as it
// reads them and the two figures it reports from the judge's JSON output.
#pragma once

#include <cstdio>
#include <regex>
#include <stdexcept>
#include <string>

#include "core/image.h"

namespace emaki::bench {

// The judge's view of a guide pass: normals mapped from [-1, 1] to [0, 1], others as they are.
inline Image<float> judge_guide(const Image<float>& pass, const std::string& name) {
  Image<float> out = pass.clone();
  if (name == "normal")
    for (int y = 0; y < out.height(); ++y)
      for (int x = 0; x < out.width(); ++x)
        for (int c = 0; c < out.channels(); ++c) out(x, y, c) = 0.5f * (out(x, y, c) + 1.0f);
  return out;
}

// The judge's figures this bench reports: `style` (is B' made of exemplar texture?) and
// `coverage` (how much of the exemplar it uses): a temporal chain that washes out to blank
// paper scores a low style energy, and only its coverage shows it.
struct JudgeFigures {
  double style = 0.0, coverage = 0.0;
};

inline double json_number(const std::string& out, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(out, m, std::regex("\"" + key + "\"\\s*:\\s*([0-9.eE+-]+)")))
    throw std::runtime_error("no " + key + " in the judge's output: " + out);
  return std::stod(m[1]);
}

inline JudgeFigures run_judge(const std::string& cmd) {
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) throw std::runtime_error("cannot run " + cmd);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  if (pclose(p) != 0) throw std::runtime_error("judge failed: " + cmd + "\n" + out);
  return {json_number(out, "style"), json_number(out, "coverage")};
}

}  // namespace emaki::bench
