// Writes on a full disk: at every point where a small tmpfs can run out, writing an image or a
// manifest either fails with one line naming the file, leaving the file that was there as it was
// and no temporary beside it, or writes a whole file that reads back as written. OpenEXR reports
// success when its last writes fail, so without the check before the rename a cut-short EXR
// replaced the good one.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "core/error.h"
#include "io/image_io.h"
#include "io/temp_file.h"
#include "store/output_store.h"
#include "tests/small_disk.h"

namespace fs = std::filesystem;

namespace emaki::io {
namespace {

// Pseudo-random samples in [0, 1]: incompressible, so the file spans many pages.
Image<float> noise(int w, int h, int c) {
  Image<float> im(w, h, c);
  uint32_t s = 12345;
  for (int y = 0; y < h; ++y)
    for (int i = 0; i < w * c; ++i) {
      s = s * 1664525u + 1013904223u;
      im.row(y)[i] = float(s >> 8) / float(1 << 24);
    }
  return im;
}

bool same(const Image<float>& a, const Image<float>& b) {
  if (a.width() != b.width() || a.height() != b.height() || a.channels() != b.channels())
    return false;
  for (int y = 0; y < a.height(); ++y)
    for (int i = 0; i < a.width() * a.channels(); ++i)
      if (a.row(y)[i] != b.row(y)[i]) return false;
  return true;
}

class DiskFull : public ::testing::Test {
 protected:
  void SetUp() override {
    disk_ = std::make_unique<test::SmallDisk>(
        ::testing::UnitTest::GetInstance()->current_test_info()->name(), 1 << 20);
    if (!disk_->mounted()) GTEST_SKIP() << "cannot mount a tmpfs here (needs root)";
  }
  void TearDown() override { disk_.reset(); }

  void expect_no_temporary() const {
    for (const auto& e : fs::directory_iterator(disk_->path()))
      EXPECT_FALSE(is_temporary_name(e.path().filename().string())) << e.path();
  }

  // Writes `image` over an older file at `name` with the disk filled to every page from full to
  // a little more than the file needs; returns how many writes failed.
  int write_at_every_fill_point(const std::string& name, const Image<float>& image,
                                const WriteOptions& wo) {
    const std::string target = *disk_ / name;
    const std::string probe = *disk_ / ("probe_" + name);
    write_image(probe, image.cview(), wo);
    const int64_t need = int64_t(fs::file_size(probe));
    const Image<float> want = read_image_float(probe);
    fs::remove(probe);
    const Image<float> old(4, 4, image.channels());
    const int64_t page = ::sysconf(_SC_PAGESIZE);
    int failed = 0, written = 0;
    for (int64_t keep = 0; keep <= need + 2 * page; keep += page) {
      write_image(target, old.cview(), wo);
      EXPECT_TRUE(disk_->leave_free(keep)) << keep;
      bool ok = false;
      try {
        write_image(target, image.cview(), wo);
        ok = true;
      } catch (const Error& e) {
        EXPECT_EQ(e.subject(), target) << e.what();
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      }
      disk_->release();
      expect_no_temporary();
      try {
        const Image<float> back = read_image_float(target);
        if (ok)
          EXPECT_TRUE(same(back, want)) << name << " with " << keep << " bytes free";
        else
          EXPECT_EQ(back.width(), 4) << "a failed write replaced " << name << ", " << keep;
      } catch (const Error& e) {
        ADD_FAILURE() << name << " with " << keep << " bytes free: " << e.what();
      }
      (ok ? written : failed) += 1;
    }
    EXPECT_GT(written, 0) << name;
    return failed;
  }

  std::unique_ptr<test::SmallDisk> disk_;
};

TEST_F(DiskFull, FloatExrIsWholeOrNotWrittenAtEveryFillPoint) {
  WriteOptions wo;
  wo.format = SampleFormat::kFloat;
  wo.channel_names = {"R", "G", "B", "A"};
  EXPECT_GT(write_at_every_fill_point("layer.exr", noise(96, 64, 4), wo), 0);
}

TEST_F(DiskFull, HalfExrIsWholeOrNotWrittenAtEveryFillPoint) {
  WriteOptions wo;
  wo.format = SampleFormat::kHalf;
  EXPECT_GT(write_at_every_fill_point("frame.exr", noise(128, 96, 3), wo), 0);
}

TEST_F(DiskFull, PngIsWholeOrNotWrittenAtEveryFillPoint) {
  WriteOptions wo;
  wo.format = SampleFormat::kU16;
  EXPECT_GT(write_at_every_fill_point("frame.png", noise(96, 64, 3), wo), 0);
}

TEST_F(DiskFull, ManifestIsWholeOrNotWrittenAtEveryFillPoint) {
  Manifest big;
  for (int i = 0; i < 600; ++i) big.push_back("key" + std::to_string(i) + " = some settings");
  const std::string target = *disk_ / "manifest";
  const int64_t page = ::sysconf(_SC_PAGESIZE);
  int failed = 0;
  for (int64_t keep = 0; keep <= 6 * page; keep += page) {
    write_manifest(target, {"old = 1"});
    EXPECT_TRUE(disk_->leave_free(keep));
    try {
      write_manifest(target, big);
    } catch (const Error& e) {
      EXPECT_EQ(e.subject(), target) << e.what();
      ++failed;
    }
    disk_->release();
    expect_no_temporary();
    const auto back = read_manifest(target);
    ASSERT_TRUE(back.has_value());
    EXPECT_TRUE(*back == big || *back == Manifest{"old = 1"}) << keep;
  }
  EXPECT_GT(failed, 0);
}

}  // namespace
}  // namespace emaki::io
