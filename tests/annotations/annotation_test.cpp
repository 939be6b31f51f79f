#include "pdvo/annotations/annotation.h"

#include <gtest/gtest.h>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {

Annotation Square(double x0, double y0, double size, const char* label = kPlaneLabel) {
  Annotation a;
  a.image_path = "img.png";
  a.image_width = 100;
  a.image_height = 80;
  a.camera = Camera::Pinhole(a.image_width, a.image_height, 90, 90, 49.5, 39.5);
  AnnotationShape s;
  s.label = label;
  s.points = {{x0, y0}, {x0 + size, y0}, {x0 + size, y0 + size}, {x0, y0 + size}};
  if (std::string(label) == kPlaneLabel) s.normal = Eigen::Vector3d(0, 0, -1);
  a.shapes.push_back(s);
  return a;
}

// The first error's message, or "" if none.
std::string FirstError(const Annotation& a) {
  for (const ValidationIssue& i : Validate(a)) {
    if (i.is_error) return i.message;
  }
  return "";
}

TEST(Annotation, WriteReadRoundTripKeepsEverything) {
  test::TempDir dir;
  Annotation a = Square(10, 10, 20);
  a.shapes[0].score = 0.75;
  a.shapes[0].group_id = 3;
  a.shapes[0].extra["description"] = "left facade";
  a.extra["flags"] = {{"reviewed", true}};
  a.shapes.push_back(Square(50, 10, 20, kNonPlaneLabel).shapes[0]);
  WriteAnnotation(dir / "a.json", a);
  const Annotation b = ReadAnnotation(dir / "a.json");
  EXPECT_EQ(b.image_path, "img.png");
  EXPECT_EQ(b.image_width, 100);
  ASSERT_TRUE(b.camera.has_value());
  EXPECT_DOUBLE_EQ(b.camera->cx, 49.5);
  ASSERT_EQ(b.shapes.size(), 2u);
  EXPECT_TRUE(b.shapes[0].IsPlane());
  EXPECT_EQ(*b.shapes[0].normal, Eigen::Vector3d(0, 0, -1));
  EXPECT_DOUBLE_EQ(*b.shapes[0].score, 0.75);
  EXPECT_EQ(b.shapes[0].extra["description"], "left facade");
  EXPECT_EQ(b.shapes[0].group_id, 3);
  EXPECT_FALSE(b.shapes[1].group_id.has_value());
  EXPECT_TRUE(b.shapes[1].IsNonPlane());
  EXPECT_FALSE(b.shapes[1].normal.has_value());
  EXPECT_EQ(b.extra["flags"]["reviewed"], true);
  // Writing what was read gives the same bytes.
  EXPECT_EQ(AnnotationToJson(b), AnnotationToJson(ReadAnnotation(dir / "a.json")));
  EXPECT_EQ(ReadFile(dir / "a.json"), AnnotationToJson(b));
}

TEST(Annotation, ReadsLabelMeRectangles) {
  const Annotation a = ParseAnnotation(
      R"({"imagePath": "x.png", "imageWidth": 10, "imageHeight": 10,
          "shapes": [{"label": "plane", "shape_type": "rectangle", "points": [[1, 2], [5, 7]]}]})",
      "r.json");
  ASSERT_EQ(a.shapes[0].points.size(), 4u);
  EXPECT_EQ(a.shapes[0].points[2], Eigen::Vector2d(5, 7));
  EXPECT_EQ(FirstError(a), "");
}

TEST(Annotation, MalformedJsonNamesTheFile) {
  test::TempDir dir;
  WriteFileAtomically(dir / "bad.json", "{\"imagePath\": \"x.png\", ");
  try {
    ReadAnnotation(dir / "bad.json");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json: malformed JSON"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadAnnotation(dir / "missing.json"), IoError);
}

TEST(Annotation, WrongTypesAndMissingKeysNameShapeAndKey) {
  auto error_of = [](const std::string& text) -> std::string {
    try {
      ParseAnnotation(text, "f.json");
    } catch (const FormatError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error_of(R"({"imageWidth": 10, "imageHeight": 10, "shapes": []})"), "f.json: missing key 'imagePath'");
  EXPECT_EQ(error_of(R"({"imagePath": "x", "imageWidth": "ten", "imageHeight": 10, "shapes": []})"),
            "f.json: 'imageWidth' must be a number");
  EXPECT_EQ(error_of(R"({"imagePath": "x", "imageWidth": 10, "imageHeight": 10, "shapes": [{"label": "plane"}]})"),
            "f.json: shape 0: missing key 'points'");
  EXPECT_EQ(error_of(R"({"imagePath": "x", "imageWidth": 10, "imageHeight": 10,
                         "shapes": [{"label": "plane", "points": [[1, 2, 3]]}]})"),
            "f.json: shape 0: each point must be [x, y]");
  EXPECT_EQ(error_of(R"({"imagePath": "x", "imageWidth": 10, "imageHeight": 10,
                         "shapes": [{"label": "plane", "points": [], "normal": [1, 2]}]})"),
            "f.json: shape 0: 'normal' must be [nx, ny, nz]");
  EXPECT_EQ(error_of(R"({"imagePath": "x", "imageWidth": 10, "imageHeight": 10,
                         "shapes": [{"label": "plane", "points": [], "group_id": "left"}]})"),
            "f.json: shape 0: 'group_id' must be an integer or null");
  EXPECT_EQ(error_of("[1, 2]"), "f.json: expected a JSON object");
  // Hostile input: refused before it is copied, allocated or converted.
  std::string deep = R"({"imagePath": "x", "imageWidth": 10, "imageHeight": 10, "shapes": [], "mine": )";
  for (int k = 0; k < 60000; ++k) deep += "{\"a\":";
  deep += "1" + std::string(60000, '}') + "}";
  EXPECT_EQ(error_of(deep), "f.json: JSON nested deeper than 64 levels");
  EXPECT_EQ(error_of(R"({"imagePath": "x", "imageWidth": 1e400, "imageHeight": 10, "shapes": []})"),
            "f.json: a number beyond the range of a double");
  EXPECT_EQ(error_of(R"({"imagePath": "x", "imageWidth": 100000, "imageHeight": 100000, "shapes": []})"),
            "f.json: 'imageWidth' must be a whole number of pixels, at most 16384 (got 100000)");
  EXPECT_EQ(error_of(R"({"imagePath": "x", "imageWidth": 1e300, "imageHeight": 10, "shapes": []})"),
            "f.json: 'imageWidth' must be a whole number of pixels, at most 16384 (got 1e+300)");
  std::string many =
      R"({"imagePath": "x", "imageWidth": 10, "imageHeight": 10, "shapes": [{"label": "plane", "points": [)";
  for (int k = 0; k < 1000000; ++k) many += (k ? ",[" : "[") + std::to_string(k % 10) + ",1]";
  EXPECT_EQ(error_of(many + "]}]}"), "f.json: shape 0: 1000000 points, more than 4096 in a shape");
  std::string shapes = R"({"imagePath": "x", "imageWidth": 10, "imageHeight": 10, "shapes": [)";
  for (int k = 0; k < 30; ++k) {
    shapes += std::string(k ? "," : "") + R"({"label": "plane", "points": [)";
    for (int i = 0; i < 4000; ++i) shapes += (i ? ",[" : "[") + std::to_string(i % 10) + ",1]";
    shapes += "]}";
  }
  EXPECT_EQ(error_of(shapes + "]}"), "f.json: more than 100000 polygon points in a file");
  EXPECT_EQ(error_of(R"({"imagePath": "x", "imageWidth": 320.7, "imageHeight": 10, "shapes": []})"),
            "f.json: 'imageWidth' must be a whole number of pixels, at most 16384 (got 320.7)");
}

TEST(Annotation, ValidAnnotationHasNoIssues) { EXPECT_TRUE(Validate(Square(10, 10, 20)).empty()); }

TEST(Annotation, EachValidationError) {
  Annotation a = Square(10, 10, 20);
  a.shapes[0].points.resize(2);
  EXPECT_EQ(FirstError(a), "polygon has 2 distinct points, needs at least 3");

  a = Square(10, 10, 20);
  a.shapes[0].points.push_back(a.shapes[0].points[0]);  // a repeated closing point is not a new point
  EXPECT_EQ(FirstError(a), "");
  a.shapes[0].points = {{10, 10}, {30, 30}, {30, 10}, {10, 30}};  // a bow tie
  EXPECT_EQ(FirstError(a), "polygon crosses itself");

  a = Square(90, 10, 20);
  EXPECT_EQ(FirstError(a), "point (110.0, 10.0) is outside the 100x80 image");
  a = Square(-0.5, -0.5, 10);  // the image's edge itself is inside
  EXPECT_EQ(FirstError(a), "");

  a = Square(10, 10, 20);
  a.shapes[0].normal = Eigen::Vector3d(std::nan(""), 0, -1);
  EXPECT_EQ(FirstError(a), "normal is not a number");
  a.shapes[0].normal = Eigen::Vector3d::Zero();
  EXPECT_EQ(FirstError(a), "normal is zero");
  a.shapes[0].normal = Eigen::Vector3d(0, 0, 1);
  EXPECT_EQ(FirstError(a), "normal points away from the camera");
  a.shapes[0].normal = Eigen::Vector3d(0, 0, -1);
  a.shapes[0].score = 1.5;
  EXPECT_EQ(FirstError(a), "score is not in [0, 1]");

  a = Square(10, 10, 30);
  a.shapes.push_back(Square(20, 20, 30, kNonPlaneLabel).shapes[0]);
  EXPECT_EQ(FirstError(a), "overlaps plane shape 0");
  // Sharing an edge is not overlapping; two planes may overlap.
  a = Square(10, 10, 20);
  a.shapes.push_back(Square(30, 10, 20, kNonPlaneLabel).shapes[0]);
  a.shapes.push_back(Square(12, 12, 10).shapes[0]);
  EXPECT_EQ(FirstError(a), "");

  a = Square(10, 10, 20);
  a.image_width = 0;
  EXPECT_EQ(FirstError(a), "image size 0x80 is not positive");
}

TEST(Annotation, NullNormalComponentIsNotANumber) {
  const Annotation a = ParseAnnotation(
      R"({"imagePath": "x.png", "imageWidth": 10, "imageHeight": 10,
          "shapes": [{"label": "plane", "points": [[1, 1], [5, 1], [5, 5]], "normal": [null, 0, -1]}]})",
      "n.json");
  EXPECT_EQ(FirstError(a), "normal is not a number");
}

TEST(Annotation, WarningsForUnknownLabelsAndNonUnitNormals) {
  Annotation a = Square(10, 10, 20);
  a.shapes[0].normal = Eigen::Vector3d(0, 0, -2);
  a.shapes.push_back(Square(40, 10, 20, "tree").shapes[0]);
  const auto issues = Validate(a);
  ASSERT_EQ(issues.size(), 2u);
  EXPECT_FALSE(issues[0].is_error);
  EXPECT_EQ(issues[0].message, "normal is not unit length (it is normalised)");
  EXPECT_FALSE(issues[1].is_error);
  EXPECT_EQ(FormatIssue(issues[1], a, "f.json"),
            "f.json: shape 1 (tree): unknown label 'tree' (ignored; use plane or non-plane)");
  EXPECT_NO_THROW(ValidateOrThrow(a, "f.json"));
  a.shapes[0].normal = Eigen::Vector3d(0, 0, 1);
  try {
    ValidateOrThrow(a, "f.json");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_STREQ(e.what(), "f.json: shape 0 (plane): normal points away from the camera");
  }
}

TEST(Annotation, PolygonHelpers) {
  const std::vector<Eigen::Vector2d> square = {{0, 0}, {4, 0}, {4, 4}, {0, 4}};
  EXPECT_DOUBLE_EQ(PolygonArea(square), 16.0);
  EXPECT_FALSE(PolygonSelfIntersects(square));
  // A concave "U" does not cross itself; one whose arm touches the other side does.
  EXPECT_FALSE(PolygonSelfIntersects({{0, 0}, {6, 0}, {6, 6}, {4, 6}, {4, 2}, {2, 2}, {2, 6}, {0, 6}}));
  EXPECT_TRUE(PolygonSelfIntersects({{0, 0}, {6, 0}, {6, 6}, {4, 6}, {4, 2}, {0, 2}, {2, 6}, {0, 6}}));
}

// Plane shapes of one group_id are one plane; a plane shape without one is a plane of its own; others none. Each
// plane's largest piece stands for it.
TEST(Annotation, PlanesOfGroupsPiecesOfOnePlane) {
  Annotation a = Square(10, 10, 20);
  for (int k = 0; k < 4; ++k) a.shapes.push_back(a.shapes[0]);
  a.shapes[1].group_id = a.shapes[3].group_id = 5;
  a.shapes[2].label = kNonPlaneLabel;
  a.shapes[4].group_id = 2;
  a.shapes[3].points = Square(40, 40, 30).shapes[0].points;  // the larger piece of plane 1: its normal is the plane's
  const AnnotationPlanes planes = PlanesOf(a);
  EXPECT_EQ(planes.of_shape, (std::vector<int>{0, 1, -1, 1, 2}));
  EXPECT_EQ(planes.largest, (std::vector<int>{0, 3, 4}));
}

TEST(Annotation, ResolvesImagePathRelativeToTheJsonFolder) {
  Annotation a;
  a.image_path = "../rgb/1.png";
  EXPECT_EQ(ResolveImagePath(a, "/data/set/annotations/1.json"), "/data/set/rgb/1.png");
}

}  // namespace
}  // namespace pdvo
