// An OpenColorIO conversion run as steps, so that its costly per-channel parts (log and
// exponent curves, the ACES tone scale's spline, the sRGB transfer) are table lookups.
//
// The processor's optimized transforms are cut into runs: a run of transforms with no channel
// crosstalk holding at least one curve becomes a table per channel, every other run stays an
// OpenColorIO processor. A table holds the run's exact values (OpenColorIO's) at 2^10 points
// per octave of |x| in [2^-32, 2^32), both signs and zero; between points it interpolates
// linearly in x (the curves are smooth between their knots). Values outside that range (tiny,
// huge, inf, NaN) go through OpenColorIO as they are. Against OpenColorIO's whole processor,
// the largest difference over colour_test's sweep is 6.6e-7 for the sRGB curve and 3.5e-6 for
// the Filmic view (there mostly OpenColorIO's own: 4x the points leave it as it is); the test
// holds it within 1e-5. Each pixel's result is its own, whatever its neighbours or its band.
#pragma once

#include <OpenColorIO/OpenColorIO.h>

#include <memory>
#include <vector>

#include "core/image.h"

namespace emaki::colour {

class Steps {
 public:
  // `processor` made in `config`; its optimized form is what is cut into steps.
  Steps(const OCIO_NAMESPACE::ConstConfigRcPtr& config,
        const OCIO_NAMESPACE::ConstProcessorRcPtr& processor);
  ~Steps();
  Steps(const Steps&) = delete;
  Steps& operator=(const Steps&) = delete;

  // The first three channels of every pixel converted in place (row bands, in parallel).
  void apply(ImageView<float> image) const;

  // How many steps are tables and how many OpenColorIO processors (for tests and benches).
  int table_steps() const;
  int processor_steps() const;

  struct Step;

 private:
  // Cuts the processor's optimized transforms into steps; false when none is a table.
  bool cut(const OCIO_NAMESPACE::ConstConfigRcPtr& config,
           const OCIO_NAMESPACE::ConstProcessorRcPtr& processor);

  std::vector<std::unique_ptr<Step>> steps_;
};

}  // namespace emaki::colour
