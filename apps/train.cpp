// pdvo train --annotations DIR... --out MODEL: trains the plane recogniser into one versioned model file (or, with
// --word-prior-of, adds the words' plane log-odds to a model trained before them).
#include <sys/resource.h>

#include <sstream>

#include "pdvo/common/errors.h"
#include "pdvo/common/logging.h"
#include "pdvo/train/trainer.h"
#include "tool.h"

namespace pdvo::apps {

int RunTrain(int argc, char** argv) {
  CLI::App app(
      "Trains the plane recogniser on annotated images (LabelMe JSON with a normal per plane, images "
      "beside them; e.g. from pdvo synth or pdvo annotate-depth): regions from the annotations, two "
      "visual vocabularies, topics, spatiograms, a committee of classifiers and normal regressors (RVMs, or "
      "OpenCV ml's SVMs, kNN or random trees: --classifier). "
      "Writes one model file (YAML) holding everything inference needs and a training card.",
      "pdvo train");
  std::vector<std::string> inputs, overrides;
  std::string out_path, config_path, verbosity = "info", classifier, prior_of;
  uint64_t seed = 1;
  int folds = 3;
  app.add_option("--annotations,-a", inputs, "Folders (or files) of annotations; give several")->required();
  app.add_option("--out,-o", out_path, "Model file to write (YAML)")->required();
  AddConfigFlags(app, &config_path, &overrides, "Training options (YAML, section 'train'; see models/README.md)",
                 "rvm.gammas=0.1,0.5");
  app.add_option("--classifier", classifier,
                 "Learner of the classifiers and normal regressors: rvm, svm, knn or trees (default: the options' "
                 "classifier, rvm)")
      ->check(CLI::IsMember({"rvm", "svm", "knn", "trees"}));
  app.add_option("--seed", seed, "Seed for sampling, k-means, topics and folds")
      ->capture_default_str()
      ->check(NotNegative());
  app.add_option("--cv", folds, "Cross-validation folds (grouped by image) to choose kernel widths; 1: none")
      ->capture_default_str()
      ->check(CLI::Range(1, 20));
  app.add_option("--word-prior-of", prior_of,
                 "Instead of training: a copy of this model (its classifiers unchanged) with each word's plane "
                 "log-odds counted over the annotations, the plane detector's words' prior (models before version 6)")
      ->check(CLI::ExistingFile);
  AddVerbosityFlag(app, &verbosity);
  PDVO_PARSE_FLAGS(app, argc, argv);
  ApplyVerbosity(verbosity);
  std::ostringstream data;
  for (size_t i = 0; i < inputs.size(); ++i) data << (i ? " " : "") << inputs[i];
  if (!prior_of.empty()) {
    PlaneModel model = PlaneModel::Read(prior_of);
    const std::vector<std::string> files = ListAnnotationFiles(inputs);
    model.word_plane_log_odds = CountWordPlaneLogOdds(model, files);
    model.card.word_prior =
        data.str() + " (" + std::to_string(files.size()) + " files; pdvo " + kVersion + ", " + kGitHash + ")";
    model.Write(out_path);
    std::printf("wrote %s: %s with its words' plane log-odds from %zu annotation files (from %.2f to %.2f)\n",
                out_path.c_str(), prior_of.c_str(), files.size(), model.word_plane_log_odds.minCoeff(),
                model.word_plane_log_odds.maxCoeff());
    return 0;
  }

  if (!classifier.empty()) overrides.push_back("classifier=" + classifier);
  const TrainOptions options = LoadToolOptions<TrainOptions>(config_path, "train", overrides);
  const std::vector<std::string> files = ListAnnotationFiles(inputs);
  PDVO_LOG(Info) << "training on " << files.size() << " annotation files";
  PlaneModel model = TrainModel(files, options, seed, folds, data.str());
  std::vector<std::string> assignments;
  OptionAssignments(options, &assignments);
  for (const std::string& a : assignments) {
    if (!model.card.training_options.empty()) model.card.training_options += ' ';
    model.card.training_options += a;
  }
  model.card.pdvo_version = kVersion;
  model.card.git_commit = kGitHash;
  model.Write(out_path);
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  std::string classifier_sizes;
  for (const Learned& f : model.classifiers) {
    if (!classifier_sizes.empty()) classifier_sizes += '/';
    classifier_sizes += std::to_string(f.size);
  }
  const char* const sizes = options.classifier == LearnerKind::kRvm   ? "relevance vectors"
                            : options.classifier == LearnerKind::kSvm ? "support vectors"
                            : options.classifier == LearnerKind::kKnn ? "samples"
                                                                      : "tree nodes";
  std::printf(
      "wrote %s: %d images, %d+%d regions per classifier, cv accuracy %.3f, cv normal error %.1f deg, "
      "%s %s (%zu %s classifiers) %d/%d/%d (normal); peak memory %.0f MiB\n",
      out_path.c_str(), model.card.images, model.card.plane_regions, model.card.non_plane_regions,
      model.card.cv_accuracy, model.card.cv_normal_error, sizes, classifier_sizes.c_str(), model.classifiers.size(),
      OptionName(options.classifier).c_str(), model.normal[0].size, model.normal[1].size, model.normal[2].size,
      usage.ru_maxrss / 1024.0);
  return 0;
}

}  // namespace pdvo::apps
