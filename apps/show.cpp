// pdvo show ANNOTATION.json --out overlay.png: the annotation drawn over its image.
#include <opencv2/imgcodecs.hpp>

#include "pdvo/annotations/annotation.h"
#include "pdvo/annotations/raster.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "tool.h"

namespace pdvo::apps {

int RunShow(int argc, char** argv) {
  CLI::App app("Draws an annotation over its image: planes tinted by their normal (with an arrow), non-planes "
               "hatched, unknown pixels untouched, and a legend.",
               "pdvo show");
  std::string annotation_path, out_path, image_path, verbosity = "info";
  OverlayOptions options;
  app.add_option("annotation", annotation_path, "Annotation file (LabelMe JSON with normals)")->required();
  app.add_option("--out,-o", out_path, "Output image (.png or .jpg)")->required();
  app.add_option("--image", image_path, "Image to draw on (default: the annotation's imagePath)");
  app.add_option("--max-width", options.max_width, "Scale larger images down to this width")->capture_default_str();
  app.add_option("--alpha", options.alpha, "Opacity of the tint, 0-1")->capture_default_str();
  app.add_flag("!--no-legend", options.legend, "Leave out the legend panel");
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);

  const Annotation annotation = ReadAnnotation(annotation_path);
  ValidateOrThrow(annotation, annotation_path);
  if (image_path.empty()) image_path = ResolveImagePath(annotation, annotation_path);
  const cv::Mat image = ReadImage(image_path, cv::IMREAD_COLOR);
  WriteImage(out_path, DrawOverlay(image, annotation, options));
  PDVO_LOG(Info) << "wrote " << out_path << " (" << annotation.shapes.size() << " shapes over " << image_path << ")";
  return 0;
}

}  // namespace pdvo::apps
