// The odometry's options: the shipped vo/config/default.yaml holds every option, at its default; modes are
// names in YAML and in --set, and an unknown one is an error naming the names; invalid values are refused.
#include "pdvo/vo/odometry.h"

#include <gtest/gtest.h>

#include <functional>
#include <set>

#include "pdvo/common/errors.h"
#include "pdvo/common/options.h"
#include "pdvo/test/support.h"

namespace pdvo::vo {
namespace {

const std::string kDefaults = PDVO_SOURCE_DIR "/vo/config/default.yaml";

// The keys of a YAML map and its nested maps, as "a.b".
std::set<std::string> Keys(const cv::FileNode& node, const std::string& prefix = "") {
  std::set<std::string> keys;
  for (const std::string& key : node.keys()) {
    const cv::FileNode child = node[key];
    if (child.isMap()) {
      const std::set<std::string> nested = Keys(child, prefix + key + ".");
      keys.insert(nested.begin(), nested.end());
    } else {
      keys.insert(prefix + key);
    }
  }
  return keys;
}

TEST(VoOptions, TheShippedFileHoldsEveryDefault) {
  EXPECT_EQ(LoadOptions<VoOptions>(kDefaults, "vo"), VoOptions{});
  cv::FileStorage written(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  written << "vo"
          << "{";
  WriteOptions(written, VoOptions{});
  written << "}";
  cv::FileStorage defaults(written.releaseAndGetString(), cv::FileStorage::READ | cv::FileStorage::MEMORY);
  cv::FileStorage shipped = OpenYamlForReading(kDefaults);
  EXPECT_EQ(Keys(shipped["vo"]), Keys(defaults["vo"]));
  EXPECT_GT(Keys(defaults["vo"]).size(), 30u);  // the keys were found (37 options)
}

TEST(VoOptions, ModesAreNames) {
  VoOptions o;
  SetOption(o, "mode", "idpp");
  EXPECT_EQ(o.mode, PlaneMode::kIdpp);
  SetOption(o, "planes.join_gate", "3");
  EXPECT_EQ(o.planes.join_gate, 3);
  try {
    SetOption(o, "mode", "pdvo2");
    FAIL() << "an unknown mode was taken";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("points, idpp"), std::string::npos) << e.what();
  }
  const test::TempDir dir;
  SaveOptions(dir / "vo.yaml", o, "vo");
  EXPECT_EQ(LoadOptions<VoOptions>(dir / "vo.yaml", "vo"), o);
  EXPECT_NE(ReadFile(dir / "vo.yaml").find("mode: idpp"), std::string::npos);
  WriteFileAtomically(dir / "bad.yaml", "%YAML:1.0\nvo:\n  mode: planes\n");
  EXPECT_THROW(LoadOptions<VoOptions>(dir / "bad.yaml", "vo"), FormatError);
}

TEST(VoOptions, InvalidValuesAreRefused) {
  const std::vector<std::function<void(VoOptions&)>> breaks = {
      [](VoOptions& o) { o.features.border = o.search.patch_half; },
      [](VoOptions& o) { o.planes.grow_radius = o.features.min_distance; },
      [](VoOptions& o) { o.motion.linear_acceleration = 0; },
      [](VoOptions& o) { o.ransac.hypotheses = 0; },
      [](VoOptions& o) { o.bootstrap.frames = -1; },
      [](VoOptions& o) { o.prior.inverse_depth = 0; },
      [](VoOptions& o) { o.search.min_ncc = 1; },
      [](VoOptions& o) { o.working_width = 10; },
  };
  for (size_t k = 0; k < breaks.size(); ++k) {
    VoOptions o;
    breaks[k](o);
    EXPECT_THROW(CheckOptionsOrThrow(o, "vo options"), InvalidArgument) << k;
  }
  EXPECT_NO_THROW(CheckOptionsOrThrow(VoOptions{}, "vo options"));
}

}  // namespace
}  // namespace pdvo::vo
