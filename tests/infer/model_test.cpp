#include "pdvo/infer/model.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/infer/recogniser.h"
#include "pdvo/test/models.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {

RvmFunction RandomRvm(int vectors, int dims, std::mt19937& rng) {
  std::normal_distribution<double> g(0, 1);
  RvmFunction f;
  f.gamma = 0.37;
  f.bias = g(rng);
  f.weights = Eigen::VectorXd::NullaryExpr(vectors, [&]() { return g(rng); });
  f.vectors = Eigen::MatrixXd::NullaryExpr(vectors, dims, [&]() { return g(rng); });
  return f;
}

// A small model with random contents: 12 gradient words, 5 colour words, 3 topics.
PlaneModel RandomModel() {
  std::mt19937 rng(11);
  PlaneModel m = test::RandomModelWithoutLearners(rng);
  const int dims = RegionFeatureDims(3);
  for (int size : {4, 2, 5}) m.classifiers.push_back(Learned::Rvm(RandomRvm(size, dims, rng), true));
  for (Learned& f : m.normal) f = Learned::Rvm(RandomRvm(3, dims, rng), false);
  m.card.data = "synthetic streets";
  m.card.images = 7;
  m.card.cv_accuracy = 0.93;
  m.card.training_options = "seed=1 rvm.gammas=0.1,0.5";
  m.card.pdvo_version = "0.1.0";
  m.card.git_commit = "abc1234";
  return m;
}

TEST(Model, RoundTripGivesTheSameBytesAndPredictions) {
  const PlaneModel m = RandomModel();
  const test::TempDir dir;
  const std::string path = dir.str() + "/model.yml";
  m.Write(path);
  const PlaneModel back = PlaneModel::Read(path);
  EXPECT_EQ(back.ToYaml(), ReadFile(path));  // re-writing a read model gives the same bytes
  // Matrices are written as their raw bytes in base64, not as text numbers (which triple the file's size).
  EXPECT_NE(ReadFile(path).find("data: !!binary"), std::string::npos);
  EXPECT_EQ(ReadFile(path).find("data: ["), std::string::npos);
  EXPECT_EQ(back.card.data, "synthetic streets");
  EXPECT_EQ(back.card.images, 7);
  EXPECT_EQ(back.card.training_options, "seed=1 rvm.gammas=0.1,0.5");
  EXPECT_EQ(back.card.pdvo_version, "0.1.0");
  EXPECT_EQ(back.card.git_commit, "abc1234");
  EXPECT_EQ(back.options, m.options);
  EXPECT_EQ(back.topics, m.topics);  // doubles round trip exactly
  EXPECT_EQ(back.word_plane_log_odds, m.word_plane_log_odds);
  std::mt19937 rng(2);
  std::normal_distribution<double> g(0, 1);
  const Eigen::VectorXd x = Eigen::VectorXd::NullaryExpr(m.feature_mean.size(), [&]() { return g(rng); });
  // Relevance vectors are stored in single precision: predictions move by a float's rounding; once read, they
  // are what they are.
  ASSERT_EQ(back.classifiers.size(), m.classifiers.size());
  for (size_t i = 0; i < m.classifiers.size(); ++i) {
    const RvmFunction &f = m.classifiers[i].rvm, &read = back.classifiers[i].rvm;
    EXPECT_EQ(read.vectors, f.vectors.cast<float>().cast<double>());
    EXPECT_NEAR(read(x), f(x), 1e-5 * (1 + std::abs(f(x))));
  }
  const RegionPrediction a = Recogniser(m).Predict(x), b = Recogniser(back).Predict(x);
  const RegionPrediction c = Recogniser(PlaneModel::FromYaml(back.ToYaml(), "again")).Predict(x);
  EXPECT_NEAR(a.plane_probability, b.plane_probability, 1e-5);
  EXPECT_LT((a.normal - b.normal).norm(), 1e-5);
  EXPECT_EQ(b.plane_probability, c.plane_probability);
  EXPECT_EQ(b.normal, c.normal);
  EXPECT_NEAR(a.normal.norm(), 1.0, 1e-12);
}

TEST(Model, PlaneProbabilityIsTheClassifiersMeanProbability) {
  const PlaneModel m = RandomModel();
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  const Eigen::VectorXd x = Eigen::VectorXd::NullaryExpr(m.feature_mean.size(), [&]() { return g(rng); });
  const Eigen::VectorXd standardised = (x - m.feature_mean).cwiseQuotient(m.feature_scale);
  double mean = 0;
  for (const Learned& f : m.classifiers) mean += 1 / (1 + std::exp(-f.rvm(standardised))) / 3;
  EXPECT_NEAR(Recogniser(m).Predict(x).plane_probability, mean, 1e-12);
  // One member alone gives its own probability, which differs from the committee's.
  PlaneModel one = m;
  one.classifiers.resize(1);
  const double alone = 1 / (1 + std::exp(-m.classifiers[0].rvm(standardised)));
  EXPECT_NEAR(Recogniser(one).Predict(x).plane_probability, alone, 1e-12);
  EXPECT_GT(std::abs(alone - mean), 1e-3);
  // At a relevance vector of the first classifier its kernel weighs fully (elsewhere, in 79 dimensions, the
  // kernels are nearly zero); the products are single precision (RvmBank), hence the tolerance.
  const Eigen::VectorXd on_vector =
      m.feature_mean + m.feature_scale.cwiseProduct(m.classifiers[0].rvm.vectors.row(0).transpose());
  const Eigen::VectorXd at = m.classifiers[0].rvm.vectors.row(0).transpose();
  double on_mean = 0, bias_only = 0;
  for (const Learned& f : m.classifiers) {
    on_mean += 1 / (1 + std::exp(-f.rvm(at))) / 3;
    bias_only += 1 / (1 + std::exp(f.rvm.bias)) / 3;
  }
  ASSERT_GT(std::abs(on_mean - bias_only), 1e-2);
  EXPECT_NEAR(Recogniser(m).Predict(on_vector).plane_probability, on_mean, 1e-5);
  one.classifiers.clear();
  EXPECT_THROW(Recogniser{one}, InvalidArgument);
}

// A constant function: no relevance vectors, f(x) = -bias.
RvmFunction Constant(double value, int dims) {
  RvmFunction f;
  f.bias = -value;
  f.weights = Eigen::VectorXd(0);
  f.vectors = Eigen::MatrixXd(0, dims);
  return f;
}

TEST(Model, RecognisedNormalsFaceTheCamera) {
  // Regressors that say n = (0.6, 0, 0.8) everywhere: a plane facing away from a camera looking along +z.
  PlaneModel m = RandomModel();
  const int dims = static_cast<int>(m.feature_mean.size());
  m.normal = {Learned::Rvm(Constant(0.6, dims), false), Learned::Rvm(Constant(0, dims), false),
              Learned::Rvm(Constant(0.8, dims), false)};
  cv::Mat image(240, 320, CV_8UC3);
  cv::theRNG().state = 5;
  cv::randu(image, 0, 255);  // noise: many salient points, no straight edges, no vertical
  const Region left{cv::Rect(20, 60, 100, 100), {}}, right{cv::Rect(220, 60, 90, 100), {}};
  for (bool fuse : {false, true}) {
    m.options.vanishing.fuse_normals = fuse;
    const Recogniser recogniser(m);
    const ImageWords words = recogniser.Describe(image);
    ASSERT_FALSE(words.edges.up_found);
    EXPECT_EQ(recogniser.Predict(Eigen::VectorXd::Zero(dims)).normal, Eigen::Vector3d(0.6, 0, 0.8));
    for (const Region& region : {left, right}) {
      const RegionPrediction p = recogniser.Recognise(words, region);
      ASSERT_TRUE(p.valid);
      // The nearest normal that faces the camera: edge-on to the ray, in the plane of the ray and the model's
      // normal, on the model's side.
      const Eigen::Vector3d ray = RegionRay(words.edges.camera, region).normalized();
      const Eigen::Vector3d model(0.6, 0, 0.8);
      ASSERT_GT(model.dot(ray), 0.1);
      EXPECT_NEAR(p.normal.norm(), 1, 1e-12);
      EXPECT_NEAR(p.normal.dot(ray), 0, 1e-12);
      EXPECT_NEAR(p.normal.dot(ray.cross(model)), 0, 1e-12);
      const auto angle = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::acos(a.dot(b)); };
      EXPECT_NEAR(angle(p.normal, model), M_PI / 2 - angle(ray, model), 1e-9);
    }
  }
}

TEST(Model, RvmFunctionIsTheKernelExpansion) {
  RvmFunction f;
  f.gamma = 0.5;
  f.bias = 0.25;
  f.weights = Eigen::Vector2d(2, -1);
  f.vectors = Eigen::MatrixXd(2, 2);
  f.vectors << 0, 0, 1, 1;
  const Eigen::Vector2d x(1, 0);  // squared distances 1 and 1
  EXPECT_NEAR(f(x), 2 * std::exp(-0.5) - std::exp(-0.5) - 0.25, 1e-15);
}

// Functions of two kernel widths that share some relevance vectors (one shares all of another's, one repeats a
// vector of its own, one has none): together, each function's value is what it gives alone, and the constant one
// alone in a width of its own adds no group.
TEST(Model, RvmBankEqualsEachFunctionAlone) {
  std::mt19937 rng(8);
  std::normal_distribution<double> g(0, 1);
  std::vector<RvmFunction> f = {RandomRvm(5, 6, rng), RandomRvm(4, 6, rng), RandomRvm(3, 6, rng), RandomRvm(2, 6, rng),
                                Constant(0.7, 6)};
  f[1].vectors.topRows(2) = f[0].vectors.middleRows(1, 2);  // shared within a width
  f[0].gamma = f[1].gamma = 0.05;  // widths at which the kernels weigh (squared distances are about 12)
  f[2].gamma = f[3].gamma = 0.2;
  f[2].vectors = f[0].vectors.topRows(3);     // the same vectors at another width
  f[3].vectors.row(1) = f[3].vectors.row(0);  // a vector twice in one function
  const RvmBank bank({&f[0], &f[1], &f[2], &f[3], &f[4]});
  ASSERT_EQ(bank.functions(), 5);
  const Eigen::MatrixXd rows = Eigen::MatrixXd::NullaryExpr(7, 6, [&]() { return g(rng); });
  const Eigen::MatrixXd values = bank.Evaluate(rows);
  ASSERT_EQ(values.rows(), 7);
  ASSERT_EQ(values.cols(), 5);
  for (int i = 0; i < 7; ++i) {
    for (int k = 0; k < 5; ++k) {
      // Single precision products (RvmBank): a few 1e-7 relative of the kernel expansion's terms.
      const double alone = f[k](rows.row(i).transpose());
      const double tolerance = 1e-5 * (1 + f[k].weights.cwiseAbs().sum());
      EXPECT_NEAR(values(i, k), alone, tolerance) << i << " " << k;
      if (k < 4) {
        EXPECT_GT(std::abs(alone + f[k].bias), 100 * tolerance) << "the kernels must weigh: " << i << " " << k;
      }
    }
  }
  EXPECT_EQ(RvmBank(std::vector<const RvmFunction*>{}).Evaluate(rows).cols(), 0);
  const RvmFunction constant = Constant(-0.4, 6);  // gamma 1: a width no other function has
  EXPECT_NEAR(RvmBank({&f[0], &constant}).Evaluate(rows)(3, 1), -0.4, 1e-15);
}

TEST(Model, OtherVersionTruncatedOrForeignFilesFailClearly) {
  const std::string text = RandomModel().ToYaml();
  const auto message_of = [](const std::string& yaml) {
    try {
      PlaneModel::FromYaml(yaml, "m.yml");
    } catch (const FormatError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string other = text;
  const std::string version = "version: " + std::to_string(kModelVersion);
  ASSERT_NE(other.find(version), std::string::npos);
  other.replace(other.find(version), version.size(), "version: 7");
  other = SealModelText(other);
  EXPECT_NE(message_of(other).find("model version 7, this build reads versions 3 to " + std::to_string(kModelVersion)),
            std::string::npos)
      << message_of(other);
  // Version 4 (the learner named, no checksum) is read.
  std::string four = text;
  four.replace(four.find(version), version.size(), "version: 4");
  four.resize(four.rfind("# crc32: "));
  EXPECT_EQ(PlaneModel::FromYaml(four, "m.yml").ToYaml(), text);
  // Version 5 (no word log-odds) is read, and gives the detector no prior.
  std::string five = text;
  five.replace(five.find(version), version.size(), "version: 5");
  const size_t odds = five.find("word_plane_log_odds:"), after = five.find("feature_mean:");
  ASSERT_TRUE(odds != std::string::npos && after > odds);
  five.erase(odds, after - odds);
  EXPECT_EQ(PlaneModel::FromYaml(SealModelText(five), "m.yml").word_plane_log_odds.size(), 0);
  // Word log-odds that do not match the vocabularies are refused.
  PlaneModel short_odds = RandomModel();
  short_odds.word_plane_log_odds.conservativeResize(16);
  EXPECT_NE(message_of(short_odds.ToYaml()).find("m.yml: the word log-odds do not match the vocabularies"),
            std::string::npos)
      << message_of(short_odds.ToYaml());
  // Version 3 (RVMs, no learner named) is read; an unknown learner is refused.
  std::string three = text;
  three.replace(three.find(version), version.size(), "version: 3");
  three.replace(three.find("learner: rvm\n"), 13, "");
  three.resize(three.rfind("# crc32: "));  // version 3 had no checksum
  EXPECT_EQ(PlaneModel::FromYaml(three, "m.yml").ToYaml(), text);
  std::string unknown = text;
  unknown.replace(unknown.find("learner: rvm"), 12, "learner: svr");
  unknown = SealModelText(unknown);
  EXPECT_NE(message_of(unknown).find("m.yml: unknown learner 'svr'"), std::string::npos) << message_of(unknown);
  // Cut at a line boundary (valid YAML, no end marker) and in the middle of a matrix.
  const std::string at_line = text.substr(0, text.rfind('\n', text.size() / 2) + 1);
  EXPECT_NE(message_of(at_line).find("m.yml"), std::string::npos);
  EXPECT_NE(message_of(at_line), "no error");
  EXPECT_NE(message_of(text.substr(0, text.size() * 3 / 4)), "no error");
  EXPECT_NE(message_of("%YAML:1.0\n---\nformat: something-else\n").find("not a pdvo-plane-model"), std::string::npos);
  EXPECT_NE(message_of("not yaml at all: [").find("m.yml"), std::string::npos);
  EXPECT_THROW(PlaneModel::Read("/nonexistent/model.yml"), IoError);
  PlaneModel none = RandomModel();
  none.classifiers.clear();
  EXPECT_NE(message_of(none.ToYaml()).find("m.yml: no classifiers"), std::string::npos) << message_of(none.ToYaml());
}

// A word's plane log-odds: its points' odds, smoothed towards the overall share by kWordPriorCounts points, against
// the overall odds; a word seen on planes and non-planes in the overall proportion says nothing.
TEST(Model, WordLogOddsAreTheSmoothedOddsAgainstTheOverallOdds) {
  const Eigen::Vector3d planes(90, 0, 10), non_planes(10, 10, 0);  // 100 of 120 points on planes
  const Eigen::VectorXd odds = WordPlaneLogOdds(planes, non_planes);
  const double share = 100.0 / 120, prior = std::log(share / (1 - share));
  for (int w = 0; w < 3; ++w) {
    const double p = planes(w) + kWordPriorCounts * share, q = non_planes(w) + kWordPriorCounts * (1 - share);
    EXPECT_NEAR(odds(w), std::log(p / q) - prior, 1e-12) << w;
  }
  EXPECT_GT(odds(0), 0);   // 90 of 100 on planes: a little more than the overall 5 in 6
  EXPECT_LT(odds(1), -1);  // only on non-planes
  EXPECT_NEAR(WordPlaneLogOdds(Eigen::Vector2d(50, 50), Eigen::Vector2d(10, 10))(0), 0, 1e-12);
  EXPECT_THROW(WordPlaneLogOdds(Eigen::Vector2d(5, 5), Eigen::Vector2d(0, 0)), InvalidArgument);
}

// CRC-32 bit by bit (the reflected polynomial 0xEDB88320), the reference for zlib's table-driven one.
uint32_t BitwiseCrc32(const std::string& bytes) {
  uint32_t crc = 0xffffffffu;
  for (const unsigned char c : bytes) {
    crc ^= c;
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

TEST(Model, ChecksumIsTheCrc32OfTheContentAndFindsEveryFlippedBit) {
  char expected[32];
  std::snprintf(expected, sizeof expected, "# crc32: %08x\n", BitwiseCrc32("123456789\n"));
  EXPECT_EQ(SealModelText("123456789"), std::string("123456789\n") + expected);
  EXPECT_EQ(BitwiseCrc32("123456789"), 0xcbf43926u);  // the standard check value
  const std::string text = RandomModel().ToYaml();
  EXPECT_EQ(SealModelText(text), text);  // sealing again changes nothing
  EXPECT_EQ(PlaneModel::FromYaml(text, "m.yml").ToYaml(), text);
  // A flipped bit anywhere (in the content, the version, the checksum line) is refused, naming the file.
  std::mt19937 random(7);
  for (int trial = 0; trial < 300; ++trial) {
    std::string flipped = text;
    const size_t at = trial < 40 ? text.size() - 1 - trial : random() % text.size();  // the last line, then anywhere
    flipped[at] = static_cast<char>(flipped[at] ^ (1 << (random() % 8)));
    try {
      PlaneModel::FromYaml(flipped, "m.yml");
      ADD_FAILURE() << "a flipped bit at byte " << at << " of " << text.size() << " was accepted";
    } catch (const FormatError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("m.yml: ", 0), 0u) << e.what();
    }
  }
  // A matrix whose data does not match its declared size (fuzzer): OpenCV's assertion becomes the file's error.
  std::string resized = text;
  const std::string rows = "feature_scale: !!opencv-matrix\n   rows: ";
  ASSERT_NE(resized.find(rows), std::string::npos);
  resized.insert(resized.find(rows) + rows.size(), "1");
  try {
    PlaneModel::FromYaml(SealModelText(resized), "m.yml");
    ADD_FAILURE() << "a matrix of the wrong size was accepted";
  } catch (const FormatError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("m.yml: malformed (OpenCV: ", 0), 0u) << e.what();
  }
  // An edit whose checksum was not renewed.
  std::string edited = text;
  edited.replace(edited.find("min_points: "), 12, "min_points: 1");
  try {
    PlaneModel::FromYaml(edited, "m.yml");
    ADD_FAILURE() << "an edited model was accepted";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("m.yml: checksum mismatch"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pdvo
