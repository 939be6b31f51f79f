// pdvo show ANNOTATION.json... --out overlay.png: annotations drawn over their images; several make a contact
// sheet.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pdvo/annotations/annotation.h"
#include "pdvo/annotations/raster.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "tool.h"

namespace pdvo::apps {

int RunShow(int argc, char** argv) {
  CLI::App app(
      "Draws annotations over their images: planes tinted by their normal (with an arrow), non-planes "
      "hatched, unknown pixels untouched, and a legend. Several annotations make a contact sheet: their "
      "overlays side by side, in rows of --columns, the images next to them with --with-image.",
      "pdvo show");
  std::vector<std::string> annotation_paths;
  std::string out_path, image_path, verbosity = "info";
  OverlayOptions options;
  int columns = 3;
  bool with_image = false;
  app.add_option("annotations", annotation_paths, "Annotation files (LabelMe JSON with normals)")->required();
  app.add_option("--out,-o", out_path, "Output image (.png or .jpg)")->required();
  app.add_option("--image", image_path, "Image to draw on (one annotation only; default: its imagePath)");
  app.add_option("--max-width", options.max_width, "Scale larger images down to this width")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--alpha", options.alpha, "Opacity of the tint, 0-1")->capture_default_str()->check(NumberIn(0, 1));
  app.add_flag("!--no-legend", options.legend, "Leave out the legend panel");
  app.add_option("--columns", columns, "Contact sheet: tiles per row")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_flag("--with-image", with_image, "Contact sheet: show each image beside its overlay");
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);
  PDVO_THROW_CHECK(image_path.empty() || annotation_paths.size() == 1, InvalidArgument,
                   "--image needs exactly one annotation");

  std::vector<cv::Mat> tiles;
  OverlayOptions tile_options = options;
  tile_options.legend = options.legend && annotation_paths.size() == 1;
  for (const std::string& path : annotation_paths) {
    const Annotation annotation = ReadAnnotation(path);
    ValidateOrThrow(annotation, path);
    const std::string image_file = image_path.empty() ? ResolveImagePath(annotation, path) : image_path;
    const cv::Mat image = ReadImage(image_file, cv::IMREAD_COLOR);
    PDVO_THROW_CHECK(image.cols == annotation.image_width && image.rows == annotation.image_height, FormatError,
                     image_file << ": the image is " << image.cols << "x" << image.rows << ", " << path << " says "
                                << annotation.image_width << "x" << annotation.image_height);
    cv::Mat tile = DrawOverlay(image, annotation, tile_options);
    if (with_image) {
      cv::Mat plain;
      cv::resize(image, plain, tile.size(), 0, 0, cv::INTER_AREA);
      cv::hconcat(plain, tile, tile);
    }
    tiles.push_back(tile);
  }
  cv::Mat out = tiles[0];
  if (tiles.size() > 1) {
    // Rows of tiles of the first tile's size, with a thin gap.
    const cv::Size tile_size = tiles[0].size();
    constexpr int kGap = 4;
    const int n = static_cast<int>(tiles.size()), cols = std::min(columns, n), rows = (n + cols - 1) / cols;
    out = cv::Mat(rows * (tile_size.height + kGap) - kGap, cols * (tile_size.width + kGap) - kGap, CV_8UC3,
                  cv::Scalar(255, 255, 255));
    for (int k = 0; k < n; ++k) {
      cv::Mat tile;
      cv::resize(tiles[k], tile, tile_size, 0, 0, cv::INTER_AREA);
      tile.copyTo(out(cv::Rect((k % cols) * (tile_size.width + kGap), (k / cols) * (tile_size.height + kGap),
                               tile_size.width, tile_size.height)));
    }
  }
  WriteImage(out_path, out);
  PDVO_LOG(Info) << "wrote " << out_path << " (" << annotation_paths.size() << " annotations)";
  return 0;
}

}  // namespace pdvo::apps
