// The plane annotation format (LabelMe JSON with a normal per plane; ../shared/ANNOTATIONS.md, v1): reading,
// writing and validation. Detections are written in the same format.
//
// Reading keeps every key it does not interpret (LabelMe's `flags`, `group_id`, `description`, ...), so a
// file read and written again loses nothing. Shapes with labels other than `plane` / `non-plane` are kept
// but reported by Validate() and skipped by consumers. A LabelMe `rectangle` (two corners) is read as a
// four-point polygon.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pdvo/common/camera.h"
#include "pdvo/common/detected_plane.h"

namespace pdvo {

inline constexpr const char* kPlaneLabel = "plane";
inline constexpr const char* kNonPlaneLabel = "non-plane";

struct AnnotationShape {
  std::string label;                      // "plane" or "non-plane"
  std::vector<Eigen::Vector2d> points;    // pixels of the full-resolution image, (0,0) = top-left pixel centre
  std::optional<Eigen::Vector3d> normal;  // planes: unit normal in the camera frame, towards the camera
  std::optional<double> score;            // detector confidence in [0, 1]
  // LabelMe's group_id: the pieces of one plane (seen on both sides of a tree, say) share it; none: the shape
  // is a plane of its own.
  std::optional<int> group_id;
  nlohmann::json extra = nlohmann::json::object();  // other keys, kept as read

  bool IsPlane() const { return label == kPlaneLabel; }
  bool IsNonPlane() const { return label == kNonPlaneLabel; }
};

struct Annotation {
  std::string version = "5.2.1";  // LabelMe version string
  std::string image_path;         // relative to the JSON file's folder
  int image_width = 0, image_height = 0;
  // The image's pinhole camera at its full resolution: the file holds fx, fy, cx, cy (px); width and height are
  // the image's, and there is no distortion.
  std::optional<Camera> camera;
  std::vector<AnnotationShape> shapes;
  nlohmann::json extra = nlohmann::json::object();  // other top-level keys (flags, ...), kept as read
};

// The planes of an annotation: plane shapes of one group_id are one plane (its pieces), every other plane shape is
// one of its own; planes numbered from 0 in the order of their first shape.
struct AnnotationPlanes {
  std::vector<int> of_shape;  // per shape, its plane; -1 for other labels
  std::vector<int> largest;   // per plane, its piece of largest polygon area, whose normal is the plane's
};
AnnotationPlanes PlanesOf(const Annotation& annotation);

// Parses JSON text; `where` names the source in errors. Throws FormatError for malformed JSON, a missing
// required key or a value of the wrong type, naming the file, the shape and the key.
Annotation ParseAnnotation(const std::string& json_text, const std::string& where);
// Reads a file; IoError if it cannot be read, FormatError as above.
Annotation ReadAnnotation(const std::string& path);
// Serialises (2-space indented JSON, `imageData: null`).
std::string AnnotationToJson(const Annotation& annotation);
// Writes atomically.
void WriteAnnotation(const std::string& path, const Annotation& annotation);

// The image file of an annotation read from `json_path`.
std::string ResolveImagePath(const Annotation& annotation, const std::string& json_path);
// Throws FormatError naming both sources unless the two annotations are of images of one size.
void CheckSameImageSize(const Annotation& reference, const std::string& reference_where, const Annotation& estimate,
                        const std::string& estimate_where);

struct ValidationIssue {
  bool is_error = true;  // false: a warning
  int shape = -1;        // index of the shape, or -1 for the file
  std::string message;
};

// Checks an annotation against the format's rules. Errors: a bad image size, a shape type other than polygon,
// fewer than 3 distinct points, a self-crossing polygon, points outside the image, a normal that is not
// finite, zero, or (with a camera) points away from the camera, a score outside [0, 1], a plane and a
// non-plane that overlap. Warnings: an unknown label, a normal on a non-plane, a normal that is not unit.
std::vector<ValidationIssue> Validate(const Annotation& annotation);
// One line per issue: "<where>: shape 2 (plane): polygon crosses itself".
std::string FormatIssue(const ValidationIssue& issue, const Annotation& annotation, const std::string& where);
// Logs the warnings and throws FormatError with the first error.
void ValidateOrThrow(const Annotation& annotation, const std::string& where);

// True if two polygon edges, other than neighbours, cross or touch. O(n^2) in the number of points.
bool PolygonSelfIntersects(const std::vector<Eigen::Vector2d>& polygon);

// The viewing ray (camera frame, z = 1) through the centroid of a polygon's distinct vertices: where Validate tests
// that a plane's normal faces the camera.
Eigen::Vector3d PolygonRay(const std::vector<Eigen::Vector2d>& polygon, const Camera& camera);

// Area of a simple polygon (shoelace), in square pixels.
double PolygonArea(const std::vector<Eigen::Vector2d>& polygon);

// The annotation's planes with a normal as detections in an image `width` px wide (the annotation's pixels
// scaled by width / image_width; their score, 1 if none). Non-planes, and planes without a normal, are left out.
std::vector<DetectedPlane> DetectedPlanes(const Annotation& annotation, int width);

}  // namespace pdvo
