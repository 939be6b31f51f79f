// What the visual odometry mapped, in the world frame: points whose inverse depth is known to 30% and planes as
// the polygon of their points (the convex hull of their keyframe pixels, on the plane), kept when they leave the
// filter; the paper's mapping statistics (Table I: planes, points per plane, plane area); and writing the map
// with the camera path as PLY.
#pragma once

#include <Eigen/Core>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "pdvo/common/trajectory.h"

namespace pdvo::vo {

class Filter;
struct PlaneTrack;
struct Tracks;

struct MapPlane {
  std::vector<Eigen::Vector3d> polygon;              // world, in order around the plane's points' convex hull
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // world, unit
  // Which plane of the odometry it is: the filter (each start of the odometry is a new one, MapRecord::NewFilter)
  // and the plane's id in it. The polygons of a plane that moved to later keyframes (its extent in each) share
  // them. -1: not known (a file written before they were).
  int filter = -1, plane = -1;
};

struct Map {
  std::vector<Eigen::Vector3d> points;  // world
  std::vector<MapPlane> planes;

  void Append(const Map& other) {
    points.insert(points.end(), other.points.begin(), other.points.end());
    planes.insert(planes.end(), other.planes.begin(), other.planes.end());
  }
};

// A plane as mapped: its most points and the largest area (convex hull of its points, keyframe pixels).
struct PlaneRecord {
  int points = 0;
  double area = 0;
};
// The paper's Table I: planes made (that reached min_plane_points), mean points per plane, mean plane area.
struct MappingStats {
  int planes = 0;
  double points_per_plane = 0;
  double mean_plane_area = 0;  // px^2, working resolution
};

// The share of its inverse depth within which a point's is known (one standard deviation) for it to be mapped.
inline constexpr double kMappedRelativeSigma = 0.3;
// The paper's Fig. 4: a plane's measurements per frame by the frames since the keyframe it was made in, the mean
// over the planes that reached `min_plane_points` distinct keyframe pixels; ages 0 .. frames - 1.
class MeasurementCurve {
 public:
  MeasurementCurve(int frames, int min_plane_points) : frames_(frames), min_plane_points_(min_plane_points) {}
  // A point of plane `plane` (made at frame `keyframe`) searched for in frame `frame`; `used`: the update used it.
  void Add(int frame, int keyframe, int plane, const Eigen::Vector2d& keyframe_pixel, bool used);
  std::vector<double> Mean() const;

 private:
  struct Counts {
    std::vector<int> used;                  // by age; empty until first used within `frames_`
    std::set<std::pair<int, int>> members;  // distinct keyframe pixels
  };
  int frames_, min_plane_points_;
  std::map<std::pair<int, int>, Counts> planes_;  // by (keyframe, plane id)
};

// True, with its world position, if point `id` of the filter is known to kMappedRelativeSigma.
bool PointInWorld(const Filter& filter, int id, Eigen::Vector3d* point_in_world);
// Plane `id` of the filter with track `track` as a polygon in the world (MapPlane::plane = id; `filter` is left
// to the caller); false if it has fewer than `min_points` points or one of its hull's rays does not meet it in
// front.
bool PlaneInWorld(const Filter& filter, int id, const PlaneTrack& track, int min_points, MapPlane* plane);
// The convex hull of a plane's points' keyframe pixels, in order around it, and its area (keyframe px^2).
std::vector<Eigen::Vector2d> PlaneHull(const PlaneTrack& track);
double PlaneArea(const PlaneTrack& track);

// The record of a run: what left the filters, and every plane that reached min_plane_points. Each start of the
// odometry is a new filter, whose ids start again (NewFilter).
class MapRecord {
 public:
  explicit MapRecord(int min_plane_points) : min_plane_points_(min_plane_points) {}
  void NewFilter();
  // Forgets what the current filter mapped (its planes' records and what it kept): the two-view bootstrap
  // replaces it with a filter of another scale, and what it mapped before is guessed depth in that other frame.
  void DiscardFilter();
  // A plane's size now: its record keeps the most points (members and those that moved away) and the largest
  // area (if it has min_plane_points).
  void Record(int plane_id, const PlaneTrack& track);
  // Keeps what a feature that leaves the filter has mapped.
  void KeepPoint(const Filter& filter, int id);
  void KeepPlane(const Filter& filter, int id, const PlaneTrack& track);
  // Keeps a plane's polygon as it is now (a plane that moves to a later keyframe keeps its extent so far), as the
  // current filter's.
  void KeepPlane(MapPlane plane);
  // Keeps everything in the filter now (before a restart).
  void KeepAll(const Filter& filter, const Tracks& tracks);

  const Map& kept() const { return kept_; }
  MappingStats stats() const;
  int min_plane_points() const { return min_plane_points_; }
  int filter_number() const { return generation_; }  // the current filter's (MapPlane::filter)

 private:
  int min_plane_points_;
  int generation_ = 0;
  std::map<std::pair<int, int>, PlaneRecord> records_;  // by (generation, plane id)
  Map kept_;
  size_t kept_points_before_ = 0, kept_planes_before_ = 0;  // kept_'s sizes when the filter started
};

// The features in the filter now, as map entries; its planes numbered as filter `filter_number`'s.
Map CurrentMap(const Filter& filter, const Tracks& tracks, int min_plane_points, int filter_number);

// ASCII PLY: vertices (x y z and an RGB colour: points grey, plane corners coloured by their normal, camera
// positions red), one face per plane polygon (its vertex indices, then its filter and plane numbers), and one
// edge per step of the camera path. Written atomically.
void WritePly(const std::string& path, const Map& map, const Trajectory& camera_path);
// Reads a file that WritePly wrote: the map (plane normals from their colour, to about half a degree; faces
// without the numbers, as written before they were, get -1) and the camera path's positions. Throws IoError or
// FormatError naming the file.
Map ReadPly(const std::string& path, std::vector<Eigen::Vector3d>* camera_path);

}  // namespace pdvo::vo
