// The shipped model (models/default/model.yml) says how it was made: its card's training options are the
// default TrainOptions, set again from the card as `pdvo train --set` would take them, and it names the version
// and the commit that trained it (models/README.md, ./run model).
#include <gtest/gtest.h>

#include <sstream>

#include "pdvo/common/options.h"
#include "pdvo/infer/model.h"
#include "pdvo/train/trainer.h"

namespace pdvo {
namespace {

TEST(ShippedModel, CardRecordsTheDefaultTrainingOptionsVersionAndCommit) {
  const PlaneModel model = PlaneModel::Read(PDVO_SOURCE_DIR "/models/default/model.yml");
  EXPECT_FALSE(model.card.pdvo_version.empty());
  EXPECT_GE(model.card.git_commit.size(), 7u);
  std::istringstream in(model.card.training_options);
  std::vector<std::string> assignments;
  for (std::string a; in >> a;) assignments.push_back(a);
  ASSERT_GT(assignments.size(), 20u);
  TrainOptions options;
  options.gradient_words = 1;  // each value is set from the card, not left at its default
  options.rvm.gammas = {9.0};
  ApplyOverrides(options, assignments);
  EXPECT_EQ(options, TrainOptions());
  EXPECT_EQ(model.word_plane_log_odds.size(), model.topics.rows());  // the detector's words' prior (version 6)
}

}  // namespace
}  // namespace pdvo
