// Cutting a vertical plane's area into runs of the image's columns where one facade ends and the next begins: where
// its colour changes (one building's facade meeting the next) or where its horizontal edges turn to another
// vanishing direction (a building's corner, where a facade meets a wall at an angle). The detector (detector.h)
// recognises each run again.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pdvo/infer/vanishing.h"

namespace pdvo {

struct ColumnCutOptions {
  double colour_penalty = 0;   // a run's price in squared CIELAB units summed over columns; 0: colour says nothing
  double azimuth_penalty = 0;  // and in robust losses of edges of mean strength; 0: the edges say nothing
  int min_width = 12;          // px: the narrowest run, unless it is the only one
  int min_pixels = 8;          // columns with fewer of the mask's pixels are left out
  double join_colour = 0;      // CIELAB units: pulses joined (below); 0: never
};

// The runs of the mask's columns (those with at least min_pixels of its pixels) that minimise the sum over runs of
//   colour / colour_penalty + turn / azimuth_penalty + 1,
// each run at least min_width px wide, by exact dynamic programming; no cut if both penalties are 0.
// - colour: each column's colour is the median of `lab` (CV_32FC3) over the mask's pixels in it (a facade's
//   windows, a minority of most columns, do not count); a run's is the sum of squared differences of its columns'
//   colours to their mean.
// - turn: the mask's edges off the vertical (vanishing.h) vote for the direction phi of horizontal lines with the
//   robust loss of AzimuthLikelihood, each weighted by its strength over the mean strength of the mask's such
//   edges; a run's is the least over phi (5-degree steps) of its edges' summed losses, small only if one direction
//   fits all of them. Nothing without a vertical (EdgePlanes::up_found) or with fewer than options.min_edges such
//   edges in the mask.
// Then, with join_colour above 0, a run no wider than the runs on both sides, whose mean colours (the mean of their
// columns') are within join_colour of each other, joins them: a facade's windows or door, which fill most of
// their columns, are not a facade of their own. Repeated until there is no such run.
// `mask`: CV_8U of `lab`'s and the edges' size. Returns the x of the first column of every run after the first,
// increasing.
std::vector<int> FacadeColumnCuts(const cv::Mat& lab, const EdgePlanes& edges, const cv::Mat& mask,
                                  const ColumnCutOptions& cut, const VanishingOptions& options);

}  // namespace pdvo
