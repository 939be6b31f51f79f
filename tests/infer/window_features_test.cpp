// Window features from summed-area tables equal the point-by-point computation (RegionFeature with the
// window's EdgeStructure, as Recognise makes it) on a rendered street with the shipped model, for windows of
// several sizes and shapes; windows off the grid are refused.
#include "pdvo/infer/window_features.h"

#include <gtest/gtest.h>

#include "pdvo/common/errors.h"
#include "pdvo/infer/vanishing.h"
#include "pdvo/sim/renderer.h"
#include "pdvo/sim/synth.h"

namespace pdvo {
namespace {

cv::Mat StreetImage() {
  sim::SynthOptions options;
  const sim::Street street = sim::GenerateStreet(options.street, 40, 7);
  const Trajectory walk = sim::WalkStreet(street, options.walk, 30, 7);
  const sim::Renderer renderer(street, options.MakeCamera(), options.render, 7);
  sim::RenderedFrame frame;
  renderer.Render({walk[20].world_from_cam}, walk[20].timestamp, 20, &frame);
  return frame.image;
}

TEST(WindowFeatures, EqualThePointByPointFeatures) {
  const Recogniser recogniser(PlaneModel::Read(PDVO_SOURCE_DIR "/models/default/model.yml"));
  const PlaneModel& model = recogniser.model();
  const ImageWords words = recogniser.Describe(StreetImage());
  const WindowFeatures windows(words, model, 8);
  int compared = 0;
  for (const cv::Size size : {cv::Size(64, 64), cv::Size(112, 56), cv::Size(48, 96), cv::Size(320, 240)}) {
    for (int y = 0; y + size.height <= 240; y += 40) {
      for (int x = 0; x + size.width <= 320; x += 56) {
        const Region region{cv::Rect(x, y, size.width, size.height), cv::Mat()};
        RegionWords r = CollectRegionWords(words, region, model.gradient_words.size(), model.colour_words.size());
        ASSERT_EQ(windows.Points(region.box), r.size()) << region.box;
        if (r.size() < model.options.min_points) continue;
        r.edge_structure = EdgeStructure(words.edges, region, model.options.vanishing);
        const Eigen::VectorXd direct = RegionFeature(r, model.topics, model.options.topic_iterations);
        const Eigen::VectorXd fast = windows.Feature(region.box);
        ASSERT_EQ(fast.size(), direct.size());
        for (Eigen::Index k = 0; k < direct.size(); ++k) {
          EXPECT_NEAR(fast[k], direct[k], 1e-8 * std::max(1.0, std::abs(direct[k]))) << region.box << " value " << k;
        }
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 30);
  EXPECT_THROW(windows.Feature(cv::Rect(4, 0, 64, 64)), InvalidArgument);
  EXPECT_THROW(windows.Feature(cv::Rect(0, 0, 64, 60)), InvalidArgument);
  EXPECT_THROW(windows.Feature(cv::Rect(288, 0, 64, 64)), InvalidArgument);
}

}  // namespace
}  // namespace pdvo
