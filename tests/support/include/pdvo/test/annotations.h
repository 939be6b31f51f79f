// Building annotations in tests (header-only; tests that include it link pdvo_annotations).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pdvo/annotations/annotation.h"

namespace pdvo::test {

// A shape of `label` through the pixel centres `points`, with a normal for planes if given.
inline AnnotationShape Shape(const std::string& label, std::vector<Eigen::Vector2d> points,
                             std::optional<Eigen::Vector3d> normal = std::nullopt) {
  AnnotationShape s;
  s.label = label;
  s.points = std::move(points);
  s.normal = normal;
  return s;
}

// The shape of `label` covering pixels [x0, x1] x [y0, y1] (pixel centres as corners).
inline AnnotationShape RectShape(const std::string& label, double x0, double y0, double x1, double y1,
                                 std::optional<Eigen::Vector3d> normal = std::nullopt) {
  return Shape(label, {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, normal);
}

// An annotation of the image `image_path` (relative to the JSON file) of the given size.
inline Annotation ImageAnnotation(const std::string& image_path, int width, int height,
                                  std::vector<AnnotationShape> shapes) {
  Annotation a;
  a.image_path = image_path;
  a.image_width = width;
  a.image_height = height;
  a.shapes = std::move(shapes);
  return a;
}

}  // namespace pdvo::test
