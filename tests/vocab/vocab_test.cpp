#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/vocab/features.h"
#include "pdvo/vocab/vocabulary.h"

namespace pdvo {
namespace {

// Blotchy noise with rectangles on it, like a cluttered scene.
cv::Mat Textured(int w, int h, unsigned seed) {
  cv::Mat image(h, w, CV_8UC3);
  std::mt19937 rng(seed);
  for (int i = 0; i < static_cast<int>(image.total() * 3); ++i) image.data[i] = static_cast<uchar>(rng() % 256);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 2.0);
  cv::normalize(image, image, 0, 255, cv::NORM_MINMAX);
  std::uniform_int_distribution<int> x(0, w - 1), y(0, h - 1), c(0, 255);
  for (int k = 0; k < 150; ++k) {
    cv::rectangle(image, cv::Rect(x(rng), y(rng), 6 + x(rng) % 20, 6 + y(rng) % 20), cv::Scalar(c(rng), c(rng), c(rng)),
                  cv::FILLED);
  }
  return image;
}

TEST(Features, PointsHaveBothDescriptorsAndWholePatches) {
  const cv::Mat image = Textured(320, 240, 1);
  FeatureOptions o;
  o.max_points = 300;
  for (const char* detector : {"fast", "gftt", "dense"}) {
    o.detector = detector;
    const Features f = ExtractFeatures(image, o);
    EXPECT_GT(f.size(), 50u) << detector << " found " << f.size();
    EXPECT_LE(f.size(), 300u) << detector;
    EXPECT_EQ(f.gradient.rows, static_cast<int>(f.size()));
    EXPECT_EQ(f.gradient.cols, kGradientDims);
    EXPECT_EQ(f.colour.cols, kColourDims);
    for (const cv::Point2f& p : f.points) {
      EXPECT_GE(p.x, o.patch_size / 2.0f);
      EXPECT_LE(p.x, image.cols - 1 - o.patch_size / 2.0f);
    }
  }
}

TEST(Features, MaskAndFlatImages) {
  const cv::Mat image = Textured(320, 240, 2);
  cv::Mat mask(240, 320, CV_8U, cv::Scalar(0));
  mask(cv::Rect(0, 0, 160, 240)).setTo(255);
  const Features f = ExtractFeatures(image, {}, mask);
  ASSERT_GT(f.size(), 0u);
  for (const cv::Point2f& p : f.points) EXPECT_LT(p.x, 160.5f);
  const Features none = ExtractFeatures(cv::Mat(100, 100, CV_8UC3, cv::Scalar(50, 50, 50)), {});
  EXPECT_EQ(none.size(), 0u);
  EXPECT_EQ(none.gradient.cols, kGradientDims);
  EXPECT_THROW(ExtractFeatures(cv::Mat(10, 10, CV_8U), {}), InvalidArgument);
  FeatureOptions bad;
  bad.detector = "orb";
  EXPECT_THROW(ExtractFeatures(image, bad), InvalidArgument);
}

TEST(Features, ColourDescriptorIsTheLabMeanOfEachCell) {
  const cv::Scalar red(30, 40, 200);
  const cv::Mat image(64, 64, CV_8UC3, red);
  FeatureOptions o;
  o.detector = "dense";
  o.grid_step = 16;
  const Features f = ExtractFeatures(image, o);
  ASSERT_GT(f.size(), 0u);
  cv::Mat lab;
  cv::cvtColor(cv::Mat(1, 1, CV_8UC3, red), lab, cv::COLOR_BGR2Lab);
  for (int k = 0; k < kColourDims; ++k)
    EXPECT_NEAR(f.colour.at<float>(0, k), lab.at<cv::Vec3b>(0)[k % 3] / 255.0f, 1e-6);
}

// The gradient descriptor turns with the image: rotating the image by 90 degrees (clockwise on screen, +90 in
// image coordinates with y down) rotates the 4x4 cells and shifts every orientation by 2 of the 8 bins.
TEST(Features, GradientDescriptorRotatesWithTheImage) {
  const cv::Mat image = Textured(97, 97, 4);
  FeatureOptions o;
  o.detector = "dense";
  cv::Mat mask(97, 97, CV_8U, cv::Scalar(0));
  mask.at<uchar>(48, 48) = 255;
  o.grid_step = 1;
  const Features a = ExtractFeatures(image, o, mask);
  cv::Mat rotated;
  cv::rotate(image, rotated, cv::ROTATE_90_CLOCKWISE);
  const Features b = ExtractFeatures(rotated, o, mask);
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 1u);
  // Pixel (x, y) goes to (96 - y, x): cell (cx, cy) goes to (3 - cy, cx).
  double worst = 0, total = 0;
  for (int cy = 0; cy < 4; ++cy) {
    for (int cx = 0; cx < 4; ++cx) {
      for (int bin = 0; bin < 8; ++bin) {
        const float va = a.gradient.at<float>(0, (cy * 4 + cx) * 8 + bin);
        const float vb = b.gradient.at<float>(0, (cx * 4 + (3 - cy)) * 8 + (bin + 2) % 8);
        worst = std::max(worst, static_cast<double>(std::abs(va - vb)));
        total += va;
      }
    }
  }
  EXPECT_GT(total, 100);   // a textured patch, not an empty descriptor
  EXPECT_LT(worst, 0.05);  // float rounding of the angles at bin borders only
}

TEST(Features, GradientDescriptorOfAStepIsOneOrientation) {
  // A vertical step, dark to bright along +x: every gradient points along +x (bin 0, or 7/0 at the border).
  cv::Mat image(40, 40, CV_8UC3, cv::Scalar(20, 20, 20));
  image(cv::Rect(20, 0, 20, 40)).setTo(cv::Scalar(220, 220, 220));
  FeatureOptions o;
  o.detector = "dense";
  o.grid_step = 1;
  cv::Mat mask(40, 40, CV_8U, cv::Scalar(0));
  mask.at<uchar>(20, 20) = 255;
  const Features f = ExtractFeatures(image, o, mask);
  ASSERT_EQ(f.size(), 1u);
  double along_x = 0, total = 0;
  for (int k = 0; k < kGradientDims; ++k) {
    total += f.gradient.at<float>(0, k);
    if (k % 8 == 0) along_x += f.gradient.at<float>(0, k);
  }
  EXPECT_GT(total, 0);
  EXPECT_NEAR(along_x / total, 1.0, 1e-4);
  // Left and right columns of cells see no edge; the middle two do.
  EXPECT_NEAR(f.gradient.at<float>(0, 0), 0, 1e-6);
  EXPECT_GT(f.gradient.at<float>(0, 8), 0);
}

// Well separated blobs: the vocabulary must put each blob in a word of its own.
cv::Mat Blobs(int per_blob, int blobs, int dims, unsigned seed, std::vector<int>* truth) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0, 0.1f);
  cv::Mat data(per_blob * blobs, dims, CV_32F);
  for (int b = 0; b < blobs; ++b) {
    for (int i = 0; i < per_blob; ++i) {
      for (int d = 0; d < dims; ++d) data.at<float>(b * per_blob + i, d) = (d == b ? 5.0f : 0.0f) + g(rng);
      truth->push_back(b);
    }
  }
  return data;
}

TEST(Vocabulary, KMeansFindsSeparatedClustersAndIsRepeatable) {
  std::vector<int> truth;
  const cv::Mat data = Blobs(100, 5, 16, 3, &truth);
  const Vocabulary v = Vocabulary::Build(data, 5, 7);
  const std::vector<int> words = v.Quantise(data);
  // Each blob maps to exactly one word, and different blobs to different words.
  std::vector<int> word_of(5, -1);
  for (size_t i = 0; i < words.size(); ++i) {
    if (word_of[truth[i]] < 0) word_of[truth[i]] = words[i];
    EXPECT_EQ(words[i], word_of[truth[i]]);
  }
  std::sort(word_of.begin(), word_of.end());
  EXPECT_EQ(std::unique(word_of.begin(), word_of.end()) - word_of.begin(), 5);
  const Vocabulary again = Vocabulary::Build(data, 5, 7);
  EXPECT_EQ(cv::norm(v.centres(), again.centres(), cv::NORM_INF), 0.0);
  EXPECT_THROW(Vocabulary::Build(data.rowRange(0, 3), 5, 7), InvalidArgument);
}

// The nearest word by brute force in double; `margin` is how much nearer it is than the second nearest.
int NearestWord(const Vocabulary& v, const cv::Mat& query, double* margin) {
  double best = 1e300, second = 1e300;
  int nearest = -1;
  for (int c = 0; c < v.size(); ++c) {
    cv::Mat a, b;
    query.convertTo(a, CV_64F);
    v.centres().row(c).convertTo(b, CV_64F);
    const double d = cv::norm(a, b, cv::NORM_L2SQR);
    if (d < best) {
      second = best, best = d, nearest = c;
    } else if (d < second) {
      second = d;
    }
  }
  *margin = second - best;
  return nearest;
}

// Quantisation is exact: each descriptor gets its nearest word, but where the two nearest words are within float
// rounding of each other (relative 1e-5 of the squared distances), on random and on real gradient descriptors.
TEST(Vocabulary, QuantisationFindsTheNearestWord) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0, 1);
  cv::Mat data(3000, 32, CV_32F), queries(1000, 32, CV_32F);
  for (int i = 0; i < static_cast<int>(data.total()); ++i) data.at<float>(i) = u(rng);
  for (int i = 0; i < static_cast<int>(queries.total()); ++i) queries.at<float>(i) = u(rng);
  const Features a = ExtractFeatures(Textured(320, 240, 21), {}), b = ExtractFeatures(Textured(320, 240, 22), {});
  ASSERT_GT(b.gradient.rows, 500);
  for (const auto& [words, query] : {std::pair{Vocabulary::Build(data, 100, 1, 10), queries},
                                     std::pair{Vocabulary::Build(a.gradient, 150, 1, 10), b.gradient}}) {
    const std::vector<int> quantised = words.Quantise(query);
    ASSERT_EQ(quantised.size(), static_cast<size_t>(query.rows));
    int exact = 0, ties = 0;
    for (int q = 0; q < query.rows; ++q) {
      double margin = 0;
      const int nearest = NearestWord(words, query.row(q), &margin);
      const double scale =
          cv::norm(query.row(q), cv::NORM_L2SQR) + cv::norm(words.centres().row(nearest), cv::NORM_L2SQR);
      if (margin < 1e-5 * scale) {
        ++ties;
      } else {
        exact += nearest == quantised[static_cast<size_t>(q)];
        EXPECT_EQ(quantised[static_cast<size_t>(q)], nearest) << "descriptor " << q;
      }
    }
    EXPECT_LT(ties, query.rows / 100);
    EXPECT_EQ(exact + ties, query.rows);
  }
  // A block boundary (256 rows) and a view that is not continuous give the same words.
  const Vocabulary v = Vocabulary::Build(data, 100, 1, 10);
  const cv::Mat wide(data.rows, 40, CV_32F, cv::Scalar(0));
  data.copyTo(wide.colRange(0, 32));
  EXPECT_EQ(v.Quantise(wide.colRange(0, 32)), v.Quantise(data));
  const std::vector<int> all = v.Quantise(data), part = v.Quantise(data.rowRange(250, 520));
  EXPECT_EQ(part, std::vector<int>(all.begin() + 250, all.begin() + 520));
  EXPECT_THROW(v.Quantise(cv::Mat(2, 31, CV_32F, cv::Scalar(0))), InvalidArgument);
}

TEST(Vocabulary, RoundTripThroughFileStorage) {
  std::vector<int> truth;
  const cv::Mat data = Blobs(50, 4, 8, 5, &truth);
  const Vocabulary v = Vocabulary::Build(data, 4, 2);
  cv::FileStorage out(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  v.Write(out, "gradient_words");
  const std::string text = out.releaseAndGetString();
  cv::FileStorage in(text, cv::FileStorage::READ | cv::FileStorage::MEMORY);
  const Vocabulary back = Vocabulary::Read(in["gradient_words"], "model");
  EXPECT_EQ(back.Quantise(data), v.Quantise(data));
  EXPECT_THROW(Vocabulary::Read(in["colour_words"], "model"), FormatError);
}

}  // namespace
}  // namespace pdvo
