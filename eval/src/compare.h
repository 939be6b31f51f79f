// What the comparisons of annotations share (private to eval/).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pdvo/annotations/annotation.h"

namespace pdvo::detail {

// The size two annotations of one image are rasterised at to compare them: the reference's, at most `max_width`
// wide. Throws FormatError (naming `what`) if they are of different image sizes.
cv::Size ComparisonSize(const Annotation& reference, const Annotation& estimate, int max_width, const char* what);

// The median (the mean of the middle two of an even count); 0 for none.
double Median(std::vector<double> values);

}  // namespace pdvo::detail
