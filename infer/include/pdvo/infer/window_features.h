// The features of many rectangular windows of one image at the cost of a few table look-ups each (the detector's
// first step, the paper's section III): every salient point's contribution to a region's feature (its words,
// its topics' spatial moments, its orientation bin's moments, its edge family's least-squares moments) is summed
// into cells of a grid, and summed-area tables over the cells give any window aligned to the grid; edge pixels
// are summed likewise per pixel. The topics' moments are summed over the window's cells instead: a topic's
// membership can be tiny in a window and large elsewhere, and a table's differences would lose it. A window's feature
// equals RegionFeature of the window (with its EdgeStructure) computed point by point, to rounding. Pixels are those of
// the working image.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "pdvo/infer/model.h"
#include "pdvo/infer/recogniser.h"

namespace pdvo {

class WindowFeatures {
 public:
  // `cell` (px): windows must start and end on multiples of it. The description and model must outlive this.
  WindowFeatures(const ImageWords& words, const PlaneModel& model, int cell);

  int cell() const { return cell_; }
  // The salient points in a window (Region::Contains: the pixel nearest to the point lies in the box).
  int Points(const cv::Rect& box) const;
  // The window's feature, as RegionFeature (not standardised); throws InvalidArgument for a box off the grid or
  // outside the image.
  Eigen::VectorXd Feature(const cv::Rect& box) const;
  // The features of many windows, one per row (the topic projections computed together).
  Eigen::MatrixXd Features(const std::vector<cv::Rect>& boxes) const;

 private:
  // A window's feature from its channel sums and its topic weights.
  Eigen::VectorXd Complete(const cv::Rect& box, const Eigen::VectorXd& sums, const Eigen::VectorXd& weights) const;
  // Sums of the channels over the cells of `box`.
  Eigen::VectorXd Sum(const cv::Rect& box) const;
  // `box` in cells; throws InvalidArgument for a box off the grid or outside the image.
  cv::Rect Cells(const cv::Rect& box) const;
  // The summed-area table's channels at a cell corner.
  const double* Corner(int row, int column) const;

  const ImageWords& words_;
  const PlaneModel& model_;
  Eigen::MatrixXd gram_;  // topics^T topics
  int cell_, columns_, rows_, channels_;
  std::vector<double> table_;        // (rows + 1) x (columns + 1) x channels, summed-area over the cells
  std::vector<double> topic_cells_;  // rows x columns x topic channels, per cell
  cv::Mat edge_table_;               // CV_64FC3 integral of (edge pixel, strength, vertical strength)
};

}  // namespace pdvo
