// `emaki synth --index-cache DIR`: the exemplar index (synth/exemplar_index.h) kept on disk, one
// file per painting, so runs on the same painting and guides skip building it. The file's name is
// a digest of the style file, each guide's source file, the weights, the patch size and k; the
// engine still checks that a loaded index was built from exactly this run's source features and
// builds a new one when not, so a stale or foreign file costs time, never a wrong result.
#pragma once

#include <memory>
#include <string>

#include "apps/emaki/synth_args.h"
#include "synth/exemplar_index.h"

namespace emaki::app {

std::string index_cache_path(const SynthArgs& args);
// The index in the file, or nullptr when there is none or it is not a valid index (said on
// stderr unless quiet).
std::shared_ptr<const synth::ExemplarIndex> load_cached_index(const std::string& path, bool quiet);
// Writes the index atomically (a temporary name in the same folder, then a rename).
void store_cached_index(const std::string& path, const synth::ExemplarIndex& index);

}  // namespace emaki::app
