#include "pdvo/annotations/annotation.h"

#include <cmath>
#include <filesystem>
#include <map>

#include "pdvo/annotations/raster.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"

namespace pdvo {
namespace {
using nlohmann::json;

// What a reader refuses before it recurses or allocates: JSON nested deeper than this (the format needs four
// levels; copying a deeper document would overflow the stack), and images larger than kMaxImageSide on a side.
constexpr int kMaxJsonDepth = 64;
// Polygon points, per shape and per file: the checks that polygons do not cross themselves compare every pair of
// a shape's edges, so these bound them (to about a second for a file).
constexpr size_t kMaxShapePoints = 4096;
constexpr size_t kMaxFilePoints = 100000;

std::string ShapeWhere(const std::string& where, size_t index) { return where + ": shape " + std::to_string(index); }

double Number(const json& value, const std::string& where, const char* key) {
  PDVO_THROW_CHECK(value.is_number(), FormatError, where << ": '" << key << "' must be a number");
  return value.get<double>();
}

const json& Required(const json& object, const char* key, const std::string& where) {
  const auto it = object.find(key);
  PDVO_THROW_CHECK(it != object.end(), FormatError, where << ": missing key '" << key << "'");
  return *it;
}

AnnotationShape ParseShape(const json& j, const std::string& where) {
  PDVO_THROW_CHECK(j.is_object(), FormatError, where << ": must be an object");
  AnnotationShape shape;
  const json& label = Required(j, "label", where);
  PDVO_THROW_CHECK(label.is_string(), FormatError, where << ": 'label' must be text");
  shape.label = label.get<std::string>();
  const json& points = Required(j, "points", where);
  PDVO_THROW_CHECK(points.is_array(), FormatError, where << ": 'points' must be a list of [x, y]");
  PDVO_THROW_CHECK(points.size() <= kMaxShapePoints, FormatError,
                   where << ": " << points.size() << " points, more than " << kMaxShapePoints << " in a shape");
  for (const json& p : points) {
    PDVO_THROW_CHECK(p.is_array() && p.size() == 2, FormatError, where << ": each point must be [x, y]");
    shape.points.emplace_back(Number(p[0], where, "points"), Number(p[1], where, "points"));
  }
  std::string type = "polygon";
  if (j.contains("shape_type") && !j["shape_type"].is_null()) {
    PDVO_THROW_CHECK(j["shape_type"].is_string(), FormatError, where << ": 'shape_type' must be text");
    type = j["shape_type"].get<std::string>();
  }
  if (type == "rectangle" && shape.points.size() == 2) {
    const Eigen::Vector2d a = shape.points[0], b = shape.points[1];
    shape.points = {a, {b.x(), a.y()}, b, {a.x(), b.y()}};
    type = "polygon";
  }
  if (j.contains("normal") && !j["normal"].is_null()) {
    const json& n = j["normal"];
    PDVO_THROW_CHECK(n.is_array() && n.size() == 3, FormatError, where << ": 'normal' must be [nx, ny, nz]");
    // JSON has no NaN: a null or a string here is the writer's way of saying "not a number".
    Eigen::Vector3d normal;
    for (int i = 0; i < 3; ++i) {
      normal[i] = n[i].is_number() ? n[i].get<double>() : std::numeric_limits<double>::quiet_NaN();
    }
    shape.normal = normal;
  }
  if (j.contains("score") && !j["score"].is_null()) shape.score = Number(j["score"], where, "score");
  if (j.contains("group_id") && !j["group_id"].is_null()) {
    PDVO_THROW_CHECK(j["group_id"].is_number_integer(), FormatError,
                     where << ": 'group_id' must be an integer or null");
    shape.group_id = j["group_id"].get<int>();
  }
  for (const auto& [key, value] : j.items()) {
    if (key != "label" && key != "points" && key != "normal" && key != "score" && key != "shape_type" &&
        key != "group_id") {
      shape.extra[key] = value;
    }
  }
  if (type != "polygon") shape.extra["shape_type"] = type;  // kept, and reported by Validate()
  return shape;
}

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// True if segments [p1,p2] and [q1,q2] intersect or touch.
bool SegmentsIntersect(const Eigen::Vector2d& p1, const Eigen::Vector2d& p2, const Eigen::Vector2d& q1,
                       const Eigen::Vector2d& q2) {
  const double d1 = Cross(q2 - q1, p1 - q1), d2 = Cross(q2 - q1, p2 - q1);
  const double d3 = Cross(p2 - p1, q1 - p1), d4 = Cross(p2 - p1, q2 - p1);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  auto on_segment = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
    return p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) && p.y() >= std::min(a.y(), b.y()) &&
           p.y() <= std::max(a.y(), b.y());
  };
  return (d1 == 0 && on_segment(q1, q2, p1)) || (d2 == 0 && on_segment(q1, q2, p2)) ||
         (d3 == 0 && on_segment(p1, p2, q1)) || (d4 == 0 && on_segment(p1, p2, q2));
}

// The polygon without repeated consecutive points.
std::vector<Eigen::Vector2d> Distinct(const std::vector<Eigen::Vector2d>& polygon) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& p : polygon) {
    if (out.empty() || (p - out.back()).norm() > 1e-9) out.push_back(p);
  }
  while (out.size() > 1 && (out.front() - out.back()).norm() <= 1e-9) out.pop_back();
  return out;
}
}  // namespace

Eigen::Vector3d PolygonRay(const std::vector<Eigen::Vector2d>& polygon, const Camera& camera) {
  const std::vector<Eigen::Vector2d> distinct = Distinct(polygon);
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : distinct) centroid += p;
  return camera.Unproject(centroid / static_cast<double>(std::max<size_t>(1, distinct.size())));
}

Annotation ParseAnnotation(const std::string& text, const std::string& where) {
  json j;
  try {
    j = json::parse(text, [&](int depth, json::parse_event_t, json&) {
      PDVO_THROW_CHECK(depth <= kMaxJsonDepth, FormatError,
                       where << ": JSON nested deeper than " << kMaxJsonDepth << " levels");
      return true;
    });
  } catch (const json::parse_error& e) {
    PDVO_THROW(FormatError, where << ": malformed JSON at byte " << e.byte);
  } catch (const json::out_of_range&) {
    PDVO_THROW(FormatError, where << ": a number beyond the range of a double");
  }
  PDVO_THROW_CHECK(j.is_object(), FormatError, where << ": expected a JSON object");
  Annotation a;
  if (j.contains("version") && j["version"].is_string()) a.version = j["version"].get<std::string>();
  const json& image_path = Required(j, "imagePath", where);
  PDVO_THROW_CHECK(image_path.is_string(), FormatError, where << ": 'imagePath' must be text");
  a.image_path = image_path.get<std::string>();
  const auto size = [&](const char* key) {
    const double v = Number(Required(j, key, where), where, key);
    PDVO_THROW_CHECK(std::abs(v) <= kMaxImageSide && v == std::floor(v), FormatError,
                     where << ": '" << key << "' must be a whole number of pixels, at most " << kMaxImageSide
                           << " (got " << v << ")");
    return static_cast<int>(v);
  };
  a.image_width = size("imageWidth");
  a.image_height = size("imageHeight");
  if (j.contains("camera") && !j["camera"].is_null()) {
    const json& c = j["camera"];
    const std::string cw = where + ": camera";
    PDVO_THROW_CHECK(c.is_object(), FormatError, cw << ": must be an object with fx, fy, cx, cy");
    Camera camera;
    camera.width = a.image_width;
    camera.height = a.image_height;
    camera.fx = Number(Required(c, "fx", cw), cw, "fx");
    camera.fy = Number(Required(c, "fy", cw), cw, "fy");
    camera.cx = Number(Required(c, "cx", cw), cw, "cx");
    camera.cy = Number(Required(c, "cy", cw), cw, "cy");
    a.camera = camera;
  }
  const json& shapes = Required(j, "shapes", where);
  PDVO_THROW_CHECK(shapes.is_array(), FormatError, where << ": 'shapes' must be a list");
  size_t points = 0;
  for (size_t i = 0; i < shapes.size(); ++i) {
    a.shapes.push_back(ParseShape(shapes[i], ShapeWhere(where, i)));
    points += a.shapes.back().points.size();
    PDVO_THROW_CHECK(points <= kMaxFilePoints, FormatError,
                     where << ": more than " << kMaxFilePoints << " polygon points in a file");
  }
  for (const auto& [key, value] : j.items()) {
    if (key != "version" && key != "imagePath" && key != "imageWidth" && key != "imageHeight" && key != "camera" &&
        key != "shapes" && key != "imageData") {
      a.extra[key] = value;
    }
  }
  return a;
}

AnnotationPlanes PlanesOf(const Annotation& a) {
  AnnotationPlanes planes;
  planes.of_shape.assign(a.shapes.size(), -1);
  std::map<int, int> of_group;
  std::vector<double> largest_area;
  for (size_t i = 0; i < a.shapes.size(); ++i) {
    if (!a.shapes[i].IsPlane()) continue;
    const int next = static_cast<int>(planes.largest.size());
    const int p = a.shapes[i].group_id ? of_group.emplace(*a.shapes[i].group_id, next).first->second : next;
    planes.of_shape[i] = p;
    const double area = PolygonArea(a.shapes[i].points);
    if (p == next) {
      planes.largest.push_back(static_cast<int>(i));
      largest_area.push_back(area);
    } else if (area > largest_area[p]) {
      planes.largest[p] = static_cast<int>(i), largest_area[p] = area;
    }
  }
  return planes;
}

Annotation ReadAnnotation(const std::string& path) { return ParseAnnotation(ReadFile(path), path); }

std::string AnnotationToJson(const Annotation& a) {
  json j;
  j["version"] = a.version;
  j["flags"] = json::object();
  for (const auto& [key, value] : a.extra.items()) j[key] = value;
  j["imagePath"] = a.image_path;
  j["imageData"] = nullptr;
  j["imageWidth"] = a.image_width;
  j["imageHeight"] = a.image_height;
  if (a.camera) j["camera"] = {{"fx", a.camera->fx}, {"fy", a.camera->fy}, {"cx", a.camera->cx}, {"cy", a.camera->cy}};
  json shapes = json::array();
  for (const AnnotationShape& s : a.shapes) {
    json js;
    js["label"] = s.label;
    js["shape_type"] = "polygon";
    js["group_id"] = s.group_id ? json(*s.group_id) : json(nullptr);
    js["flags"] = json::object();
    for (const auto& [key, value] : s.extra.items()) js[key] = value;
    json points = json::array();
    for (const auto& p : s.points) points.push_back({p.x(), p.y()});
    js["points"] = points;
    if (s.normal) js["normal"] = {s.normal->x(), s.normal->y(), s.normal->z()};
    if (s.score) js["score"] = *s.score;
    shapes.push_back(js);
  }
  j["shapes"] = shapes;
  return j.dump(1) + "\n";
}

void WriteAnnotation(const std::string& path, const Annotation& annotation) {
  WriteFileAtomically(path, AnnotationToJson(annotation));
}

std::string ResolveImagePath(const Annotation& annotation, const std::string& json_path) {
  const std::filesystem::path folder = std::filesystem::path(json_path).parent_path();
  return (folder / annotation.image_path).lexically_normal().string();
}

void CheckSameImageSize(const Annotation& reference, const std::string& reference_where, const Annotation& estimate,
                        const std::string& estimate_where) {
  PDVO_THROW_CHECK(
      estimate.image_width == reference.image_width && estimate.image_height == reference.image_height, FormatError,
      estimate_where << ": the image is " << estimate.image_width << "x" << estimate.image_height << ", "
                     << reference_where << " says " << reference.image_width << "x" << reference.image_height);
}

bool PolygonSelfIntersects(const std::vector<Eigen::Vector2d>& polygon_in) {
  const std::vector<Eigen::Vector2d> polygon = Distinct(polygon_in);
  const size_t n = polygon.size();
  if (n < 4) return false;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a1 = polygon[i];
    const Eigen::Vector2d& a2 = polygon[(i + 1) % n];
    const double min_x = std::min(a1.x(), a2.x()), max_x = std::max(a1.x(), a2.x());
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours through the closing edge
      const Eigen::Vector2d& b1 = polygon[j];
      const Eigen::Vector2d& b2 = polygon[(j + 1) % n];
      if (std::max(b1.x(), b2.x()) < min_x || std::min(b1.x(), b2.x()) > max_x) continue;
      if (SegmentsIntersect(a1, a2, b1, b2)) return true;
    }
  }
  return false;
}

double PolygonArea(const std::vector<Eigen::Vector2d>& polygon) {
  double twice = 0;
  for (size_t i = 0; i < polygon.size(); ++i) twice += Cross(polygon[i], polygon[(i + 1) % polygon.size()]);
  return std::abs(twice) / 2;
}

std::vector<DetectedPlane> DetectedPlanes(const Annotation& a, int width) {
  PDVO_THROW_CHECK(a.image_width > 0 && width > 0, InvalidArgument,
                   "DetectedPlanes: image width " << a.image_width << " to " << width);
  const double scale = static_cast<double>(width) / a.image_width;
  std::vector<DetectedPlane> out;
  for (const AnnotationShape& s : a.shapes) {
    if (!s.IsPlane() || !s.normal) continue;
    DetectedPlane& p = out.emplace_back();
    for (const Eigen::Vector2d& q : s.points) p.polygon.push_back(scale * q);
    p.normal = s.normal->normalized();
    p.score = s.score.value_or(1.0);
  }
  return out;
}

std::vector<ValidationIssue> Validate(const Annotation& a) {
  std::vector<ValidationIssue> issues;
  auto error = [&](int shape, std::string message) { issues.push_back({true, shape, std::move(message)}); };
  auto warning = [&](int shape, std::string message) { issues.push_back({false, shape, std::move(message)}); };
  if (a.image_width <= 0 || a.image_height <= 0) {
    error(-1,
          "image size " + std::to_string(a.image_width) + "x" + std::to_string(a.image_height) + " is not positive");
    return issues;
  }
  if (a.camera &&
      !(a.camera->fx > 0 && a.camera->fy > 0 && std::isfinite(a.camera->cx) && std::isfinite(a.camera->cy))) {
    error(-1, "camera intrinsics are not valid (fx, fy must be positive)");
  }
  bool geometry_ok = true;
  for (size_t i = 0; i < a.shapes.size(); ++i) {
    const AnnotationShape& s = a.shapes[i];
    const int index = static_cast<int>(i);
    if (!s.IsPlane() && !s.IsNonPlane()) {
      warning(index, "unknown label '" + s.label + "' (ignored; use plane or non-plane)");
      continue;
    }
    if (s.extra.contains("shape_type")) {
      error(index, "shape type '" + s.extra["shape_type"].get<std::string>() + "' is not supported (use polygon)");
      geometry_ok = false;
      continue;
    }
    bool finite = true;
    for (const auto& p : s.points) finite = finite && p.allFinite();
    if (!finite) {
      error(index, "a point is not finite");
      geometry_ok = false;
      continue;
    }
    const auto distinct = Distinct(s.points);
    if (distinct.size() < 3) {
      error(index, "polygon has " + std::to_string(distinct.size()) + " distinct points, needs at least 3");
      geometry_ok = false;
      continue;
    }
    if (PolygonSelfIntersects(s.points)) {
      error(index, "polygon crosses itself");
      geometry_ok = false;
    }
    // Pixel centres run from 0 to size-1; the image's edge is half a pixel further out.
    for (const auto& p : s.points) {
      if (p.x() < -0.5 || p.y() < -0.5 || p.x() > a.image_width - 0.5 || p.y() > a.image_height - 0.5) {
        char buf[160];
        std::snprintf(buf, sizeof(buf), "point (%.1f, %.1f) is outside the %dx%d image", p.x(), p.y(), a.image_width,
                      a.image_height);
        error(index, buf);
        break;
      }
    }
    if (s.score && !(*s.score >= 0 && *s.score <= 1)) error(index, "score is not in [0, 1]");
    if (!s.normal) continue;
    if (s.IsNonPlane()) {
      warning(index, "a non-plane has a normal (ignored)");
      continue;
    }
    const Eigen::Vector3d& n = *s.normal;
    if (!n.allFinite()) {
      error(index, "normal is not a number");
      continue;
    }
    if (n.norm() < 1e-6) {
      error(index, "normal is zero");
      continue;
    }
    if (std::abs(n.norm() - 1) > 1e-3) warning(index, "normal is not unit length (it is normalised)");
    if (a.camera) {
      // The plane is seen, so the camera is on its front side: the normal faces every viewing ray in the
      // polygon. Tested at the centroid of the vertices.
      if (n.dot(PolygonRay(distinct, *a.camera)) >= 0) error(index, "normal points away from the camera");
    }
  }
  if (geometry_ok) {
    for (const auto& overlap : FindLabelConflicts(a)) {
      error(overlap.second, "overlaps plane shape " + std::to_string(overlap.first));
    }
  }
  return issues;
}

std::string FormatIssue(const ValidationIssue& issue, const Annotation& annotation, const std::string& where) {
  std::string line = where + ": ";
  if (issue.shape >= 0) {
    line += "shape " + std::to_string(issue.shape) + " (" + annotation.shapes[issue.shape].label + "): ";
  }
  return line + issue.message;
}

void ValidateOrThrow(const Annotation& annotation, const std::string& where) {
  for (const ValidationIssue& issue : Validate(annotation)) {
    PDVO_THROW_CHECK(!issue.is_error, FormatError, FormatIssue(issue, annotation, where));
    PDVO_LOG(Warning) << FormatIssue(issue, annotation, where);
  }
}

}  // namespace pdvo
