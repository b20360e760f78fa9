// The output folder of a shot: its layout (OutputPaths) and the Store that keeps layer results
// and per-frame outputs there, every write atomic, each set of files under a manifest of the
// settings that made it (store/settings_manifests.h).
#pragma once

#include <functional>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "io/image_io.h"
#include "pipeline/frames.h"
#include "pipeline/run.h"
#include "pipeline/shot_description.h"
#include "store/output_store.h"

namespace emaki::io {

// What an error about stale outputs tells the user to do.
inline constexpr const char* kRedoHint =
    "run `emaki run` to redo it (`emaki run --force` redoes everything)";

// The file beside a layer's (or the composites') frames naming the settings that made them.
inline constexpr const char* kManifest = ".emaki-manifest";

// The output folder's layout.
struct OutputPaths {
  std::string folder;
  std::string layer_exr(const std::string& layer, int frame) const;
  std::string layer_png(const std::string& layer, int frame) const;
  // A temporal layer's field (the next frame's warm start), hidden beside its frame.
  std::string layer_field(const std::string& layer, int frame) const;
  std::string composite_png(int frame) const;
  std::string composite_exr(int frame) const;
  std::string layered_exr(int frame) const;
  std::string mp4() const;
  std::string contact_sheet() const;
  std::string passes_file(int frame) const;  // the farm's pass cache (store/mapped_passes.h)
  // Beside a frame's cached passes: its advection fields (store/kept_fields.h).
  std::string passes_fields(int frame) const;
};

// Who else may write the folder meanwhile.
enum class StoreAccess {
  kAlone,     // nobody: an exclusive lock, and temporaries a killed run left are removed
  kFarmTask,  // other tasks of the same shot (disjoint files): a shared lock, no clean-up, and
              // every manifest must already be current (the shot's prepare task made it so)
  kInspect,   // anyone: reads what is finished (a farm's plan and status) without a lock,
              // creating nothing; writing is an invariant violation
};

enum class StoreMode {
  kRun,           // layers made with other settings are redone (emaki run)
  kReadFinished,  // they are an error naming the layer (emaki composite, qa flicker)
};

// Layer frames and composited frames each carry a manifest of the settings that made them
// (store/settings_manifests.h). Files made under other settings are never read back: `kRun` deletes
// and redoes them on the first write, `kReadFinished` throws emaki::Error naming the folder.
class FileStore : public pipeline::Store {
 public:
  // Creates the folders, locks the output folder (emaki::Error naming the holder when another
  // emaki has it) and removes temporary files a killed run left behind.
  explicit FileStore(const pipeline::Shot& shot, StoreMode mode = StoreMode::kRun,
                     StoreAccess access = StoreAccess::kAlone);
  ~FileStore() override;
  // Brings every manifest (layers, composites, the pass cache) up to date now, deleting frames
  // made with other settings: what the farm's prepare task does before the other tasks run.
  void prepare();
  // The pass cache: a scene source's guide passes per frame, rendered once and read by every
  // task of the shot (floats as in memory, read by mapping the file: store/mapped_passes.h).
  bool has_passes(int frame) const;
  // Every manifest the farm's tasks write under is current (the pass cache's only when
  // `with_pass_cache`): the prepare task has nothing left to do.
  bool prepared(bool with_pass_cache) const;
  void write_passes(int frame, ImageView<const float> passes);
  // The frame's advection fields (pipeline::advection_fields) beside its passes; written before
  // them, so a frame whose passes are there has its fields too.
  void write_kept_fields(int frame, const std::vector<pipeline::KeptField>& fields);
  bool has_layer(const pipeline::Layer& layer, int frame) const override;
  Image<float> read_layer(const pipeline::Layer& layer, int frame) const override;
  void write_layer(const pipeline::Layer& layer, int frame, ImageView<const float> value) override;
  // Every finished frame's field is kept (compressed, store/field_file.h, about a tenth of the
  // uncompressed 8 bytes a pixel), so a run of frames a-b inside a finished shot starts frame a
  // from frame a - 1's field exactly as the uninterrupted run did. The field file is read as
  // hostile input: anything but the exact header (magic, version, frame, the shot's size, the
  // digest) and a stream of exactly the shot's size gives an empty field (the frame then runs the
  // whole pyramid), never a crash; the synthesizer draws any entry outside the exemplar at random.
  void write_field(const pipeline::Layer& layer, int frame, ImageView<const int32_t> nnf,
                   uint64_t digest) override;
  void remove_field(const pipeline::Layer& layer, int frame) override;
  // OUTPUT/qa/KIND/LAYER/frame_NNNN.png (store/qa_maps.h): the maps of the last run or qa
  // command that made them.
  void write_qa_map(const std::string& kind, const pipeline::Layer& layer, int frame,
                    ImageView<const float> map) override;
  Image<int32_t> read_field(const pipeline::Layer& layer, int frame,
                            uint64_t digest) const override;
  bool has_frame(int frame) const override;
  void write_frame(int frame, ImageView<const float> composite,
                   const std::vector<ImageView<const float>>& layers,
                   ImageView<const float> passes) override;
  const OutputPaths& paths() const { return paths_; }

 private:
  // The composite's colour space (colour.h): color_picking or scene_linear, resolved.
  std::string working_space() const;
  WriteOptions exr_options() const;
  struct Manifested {
    Manifest want;         // the settings of the shot as it is now
    bool current = false;  // the files on disk were made with them
    std::string stale;     // !current and something is there: what changed
  };
  const Manifested& layer_state(const pipeline::Layer& layer) const;
  // The manifest in `dir` against `want` (`prefix`/`exts`: the frame files it covers).
  static Manifested manifested(const std::string& dir, Manifest want, const std::string& prefix,
                               std::initializer_list<const char*> exts);
  // Deletes the frames of `folder` made under other settings and records `m.want` there.
  void make_current(Manifested& m, const std::string& folder,
                    const std::function<void(const std::string&)>& remove_frames_in);

  const pipeline::Shot& shot_;
  StoreMode mode_;
  StoreAccess access_;
  OutputPaths paths_;
  std::unique_ptr<FolderLock> lock_;
  std::map<std::string, Manifested> layers_;
  Manifested frames_;
  Manifested passes_;
};

// `frames` with the shot's pass cache in front of it, when the cache holds passes made under the
// shot's current source settings (otherwise `frames` as it is).
std::unique_ptr<pipeline::FrameSource> with_pass_cache(
    const pipeline::Shot& shot, std::unique_ptr<pipeline::FrameSource> frames);

}  // namespace emaki::io
