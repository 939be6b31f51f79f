#include "pdvo/common/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {

// The shipped camera file of the TUM Freiburg 1 sequences.
Camera TumFr1() { return Camera::Read(PDVO_SOURCE_DIR "/config/cameras/tum_fr1.yaml"); }

TEST(Camera, YamlRoundTrip) {
  test::TempDir dir;
  const Camera c = TumFr1();
  c.Write(dir / "camera.yaml");
  EXPECT_EQ(Camera::Read(dir / "camera.yaml"), c);
}

TEST(Camera, ReadsARootMapWithoutDistortion) {
  test::TempDir dir;
  WriteFileAtomically(dir / "c.yaml", "%YAML:1.0\nwidth: 320\nheight: 240\nfx: 300\nfy: 301\ncx: 160\ncy: 120\n");
  const Camera c = Camera::Read(dir / "c.yaml");
  EXPECT_EQ(c.width, 320);
  EXPECT_DOUBLE_EQ(c.fy, 301);
  EXPECT_FALSE(c.HasDistortion());
}

TEST(Camera, MissingKeyIsAnErrorNamingFileAndKey) {
  test::TempDir dir;
  WriteFileAtomically(dir / "c.yaml", "%YAML:1.0\nwidth: 320\nheight: 240\nfx: 300\nfy: 301\ncx: 160\n");
  try {
    Camera::Read(dir / "c.yaml");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("c.yaml: missing key 'cy'"), std::string::npos) << e.what();
  }
}

TEST(Camera, BadValuesAndUnknownKeysAreErrors) {
  test::TempDir dir;
  WriteFileAtomically(dir / "a.yaml", "%YAML:1.0\nwidth: 320\nheight: 240\nfx: -3\nfy: 301\ncx: 160\ncy: 1\n");
  EXPECT_THROW(Camera::Read(dir / "a.yaml"), FormatError);
  WriteFileAtomically(dir / "b.yaml", "%YAML:1.0\nwidth: 320\nheight: 240\nfx: 3\nfy: 301\ncx: 160\ncy: 1\nk4: 0.1\n");
  EXPECT_THROW(Camera::Read(dir / "b.yaml"), FormatError);
  EXPECT_THROW(Camera::Read(dir / "missing.yaml"), IoError);
  // Sizes are checked before they become ints or allocate anything.
  for (const char* width : {"100000", "1e300", "-1e300", "320.7", "0"}) {
    WriteFileAtomically(dir / "c.yaml",
                        std::string("%YAML:1.0\nwidth: ") + width + "\nheight: 240\nfx: 3\nfy: 3\ncx: 1\ncy: 1\n");
    try {
      Camera::Read(dir / "c.yaml");
      ADD_FAILURE() << width << " was accepted";
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find("c.yaml: 'width' must be a whole number of pixels from 1 to 16384"),
                std::string::npos)
          << e.what();
    }
  }
  WriteFileAtomically(dir / "c.yaml", "%YAML:1.0\nwidth: .nan\nheight: 240\nfx: 3\nfy: 3\ncx: 1\ncy: 1\n");
  try {
    Camera::Read(dir / "c.yaml");
    ADD_FAILURE() << "a NaN width was accepted";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("c.yaml.width: expected a finite number"), std::string::npos) << e.what();
  }
}

TEST(Camera, UnprojectInvertsProjectWithStrongDistortion) {
  const Camera c = TumFr1();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 640), v(0, 480);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector2d pixel(u(rng), v(rng));
    const Eigen::Vector3d ray = c.Unproject(pixel);
    EXPECT_LT((c.Project(2.5 * ray) - pixel).norm(), 1e-6) << pixel.transpose();
  }
}

TEST(Camera, ProjectMatchesOpenCV) {
  const Camera c = TumFr1();
  std::vector<cv::Point3d> points = {{0.1, -0.2, 1.0}, {-0.4, 0.3, 1.5}, {0.0, 0.0, 2.0}};
  std::vector<cv::Point2d> expected;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), c.K(),
                    cv::Mat(1, 5, CV_64F, const_cast<double*>(c.distortion.data())), expected);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d p = c.Project({points[i].x, points[i].y, points[i].z});
    EXPECT_NEAR(p.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(p.y(), expected[i].y, 1e-9);
  }
}

TEST(Camera, RescaleKeepsPixelCentresAndRays) {
  const Camera c = TumFr1().Undistorted();
  const Camera half = c.Rescaled(320, 240);
  EXPECT_DOUBLE_EQ(half.fx, c.fx / 2);
  // The same ray hits corresponding places: u_half = (u + 0.5) / 2 - 0.5.
  const Eigen::Vector3d point(0.3, -0.1, 2.0);
  const Eigen::Vector2d full = c.Project(point), small = half.Project(point);
  EXPECT_NEAR(small.x(), (full.x() + 0.5) / 2 - 0.5, 1e-12);
  EXPECT_NEAR(small.y(), (full.y() + 0.5) / 2 - 0.5, 1e-12);
}

TEST(Camera, WithFieldOfViewSeesItsFieldOfView) {
  const Camera c = Camera::WithFieldOfView(320, 240, 90);
  EXPECT_FALSE(c.HasDistortion());
  EXPECT_DOUBLE_EQ(c.fx, c.fy);
  // The outer edges of the outermost pixels lie 45 degrees either side of the axis; the centre is on it.
  EXPECT_NEAR(c.Unproject({-0.5, 119.5}).x(), -1, 1e-12);
  EXPECT_NEAR(c.Unproject({319.5, 119.5}).x(), 1, 1e-12);
  EXPECT_NEAR(c.Unproject({159.5, 119.5}).norm(), 1, 1e-12);
  EXPECT_NEAR(Camera::WithFieldOfView(320, 240, 60).fx, 160 / std::tan(M_PI / 6), 1e-9);
  EXPECT_THROW(Camera::WithFieldOfView(320, 240, 180), InvalidArgument);
  EXPECT_THROW(Camera::WithFieldOfView(0, 240, 60), InvalidArgument);
}

TEST(Camera, UndistortedImageAgreesWithUndistortedPoints) {
  // A white dot at a distorted pixel must appear, after Undistorter, at UndistortPoints of that pixel.
  const Camera c = TumFr1();
  const Undistorter undistorter(c);
  for (const cv::Point2d dot : {cv::Point2d(100, 80), cv::Point2d(500, 400), cv::Point2d(320, 240)}) {
    cv::Mat image(480, 640, CV_32F, cv::Scalar(0));
    cv::circle(image, cv::Point(dot), 3, cv::Scalar(1), cv::FILLED);
    const cv::Mat out = undistorter.Apply(image);
    const cv::Moments m = cv::moments(out);
    const cv::Point2d expected = c.UndistortPoints({dot})[0];
    EXPECT_NEAR(m.m10 / m.m00, expected.x, 0.5);
    EXPECT_NEAR(m.m01 / m.m00, expected.y, 0.5);
  }
  EXPECT_THROW(undistorter.Apply(cv::Mat(10, 10, CV_8U)), InvalidArgument);
}

}  // namespace
}  // namespace pdvo
