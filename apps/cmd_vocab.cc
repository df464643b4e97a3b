// detslam vocab: trains the bag-of-words vocabulary tree on a set of images (`train`), describes a
// vocabulary file (`info`) and prints the bag-of-words scores between images (`score`); see
// src/detslam/place/vocabulary.h.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "commands.h"
#include "detslam/core/check.h"
#include "detslam/core/rng.h"
#include "detslam/features/orb_extractor.h"
#include "detslam/place/default_vocabulary.h"
#include "detslam/place/vocabulary.h"

namespace detslam::app {
namespace {

namespace fs = std::filesystem;

bool IsImageFile(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".pgm" ||
         ext == ".ppm";
}

// Image paths of an image file (itself), a folder (its image files, sorted by name) or a list
// file: one image per line, relative to the list's folder; blank lines and '#' comments skipped;
// of several fields on a line (a TUM rgb.txt: "timestamp path") the last one is the path.
std::vector<std::string> ImagesOf(const std::string& source) {
  std::vector<std::string> images;
  std::error_code ec;
  if (fs::is_directory(source, ec)) {
    for (const auto& entry : fs::directory_iterator(source, ec)) {
      if (entry.is_regular_file() && IsImageFile(entry.path())) {
        images.push_back(entry.path().string());
      }
    }
    if (ec) throw InputError(source, 0, "cannot list the folder: " + ec.message());
    std::sort(images.begin(), images.end());
  } else if (IsImageFile(source) && fs::is_regular_file(source, ec)) {
    images.push_back(source);
  } else {
    std::ifstream in(source);
    if (!in) throw InputError(source, 0, "no such folder or readable image list");
    const fs::path base = fs::path(source).parent_path();
    std::string line;
    while (std::getline(in, line)) {
      std::istringstream fields(line);
      std::string first, last;
      if (!(fields >> first) || first[0] == '#') continue;
      last = first;
      for (std::string field; fields >> field;) last = field;
      images.push_back(fs::path(last).is_absolute() ? last : (base / last).string());
    }
  }
  if (images.empty()) throw InputError(source, 0, "no images found");
  return images;
}

// Every image's descriptors, with progress on stderr.
std::vector<cv::Mat> ExtractAll(const std::vector<std::string>& images, int features) {
  OrbOptions orb;
  orb.num_features = features;
  const OrbExtractor extractor(orb);
  std::vector<cv::Mat> descriptors;
  size_t total = 0;
  for (size_t i = 0; i < images.size(); ++i) {
    const cv::Mat gray = cv::imread(images[i], cv::IMREAD_GRAYSCALE);
    if (gray.empty()) throw InputError(images[i], 0, "cannot read the image");
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat d;
    extractor.Extract(gray, cv::Mat(), &keypoints, &d);
    total += d.rows;
    descriptors.push_back(d);
    if ((i + 1) % 10 == 0 || i + 1 == images.size()) {
      std::cerr << "\rvocab: images read " << i + 1 << " / " << images.size() << " (" << total
                << " descriptors)" << std::flush;
    }
  }
  std::cerr << "\n";
  return descriptors;
}

void Train(const std::vector<std::string>& sources, const std::string& out,
           const VocabularyOptions& options, uint64_t seed, int features, int max_images) {
  std::string error;
  if (!options.Check(&error)) throw InputError("detslam vocab train: " + error);
  if (features < 1) throw InputError("detslam vocab train: --features must be >= 1");
  std::vector<std::string> images;
  for (const auto& source : sources) {
    const auto more = ImagesOf(source);
    images.insert(images.end(), more.begin(), more.end());
  }
  if (max_images > 0 && images.size() > static_cast<size_t>(max_images)) {
    // Evenly spaced over the whole set, so that a long sequence is sampled end to end.
    std::vector<std::string> picked;
    for (int i = 0; i < max_images; ++i) picked.push_back(images[i * images.size() / max_images]);
    images = std::move(picked);
  }
  const std::vector<cv::Mat> descriptors = ExtractAll(images, features);
  Rng rng(seed);
  Vocabulary vocabulary;
  vocabulary.Train(descriptors, options, rng, [](const VocabularyProgress& p) {
    if (p.nodes_done == p.nodes_at_level || p.nodes_done % 100 == 0) {
      std::cerr << "\rvocab: level " << p.level << " / " << p.levels << ": nodes " << p.nodes_done
                << " / " << p.nodes_at_level << std::flush;
      if (p.nodes_done == p.nodes_at_level) std::cerr << "\n";
    }
  });
  vocabulary.Save(out);
  std::cout << "vocabulary: " << out << " (" << vocabulary.size() << " words, "
            << vocabulary.num_nodes() << " nodes, " << images.size() << " images)\n";
}

void PrintVocabularyInfo(const std::string& path) {
  Vocabulary vocabulary;
  vocabulary.Load(path);
  std::cout << "file: " << path << "\n"
            << "format version: " << Vocabulary::kFormatVersion << "\n"
            << "k: " << vocabulary.k() << "\n"
            << "levels: " << vocabulary.levels() << "\n"
            << "words: " << vocabulary.size() << "\n"
            << "nodes: " << vocabulary.num_nodes() << "\n"
            << "training images: " << vocabulary.training_images() << "\n";
}

// Pairwise L1 scores of the images' bag-of-words vectors (as SLAM computes them: the extractor's
// default features), one row per image.
void Score(const std::string& vocabulary_path, const std::vector<std::string>& sources) {
  Vocabulary vocabulary;
  vocabulary.Load(vocabulary_path.empty() ? DefaultVocabularyPath() : vocabulary_path);
  std::vector<std::string> images;
  for (const auto& source : sources) {
    const auto more = ImagesOf(source);
    images.insert(images.end(), more.begin(), more.end());
  }
  std::vector<BowVector> bows;
  for (const cv::Mat& d : ExtractAll(images, OrbOptions{}.num_features)) {
    bows.push_back(vocabulary.Transform(d));
  }
  for (size_t i = 0; i < images.size(); ++i) {
    std::printf("%-40s", fs::path(images[i]).filename().string().c_str());
    for (size_t j = 0; j < images.size(); ++j) std::printf(" %.3f", Vocabulary::Score(bows[i], bows[j]));
    std::printf("\n");
  }
}

}  // namespace

void AddVocabCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("vocab", "Train or describe a bag-of-words vocabulary");
  cmd->require_subcommand(1);

  auto* train = cmd->add_subcommand("train", "Train a vocabulary tree on ORB features of images");
  auto sources = std::make_shared<std::vector<std::string>>();
  auto out = std::make_shared<std::string>();
  auto options = std::make_shared<VocabularyOptions>();
  auto seed = std::make_shared<uint64_t>(1);
  auto features = std::make_shared<int>(OrbOptions{}.num_features);
  auto max_images = std::make_shared<int>(0);
  train
      ->add_option("--images", *sources,
                   "Image folders or list files (one path per line, or TUM rgb.txt)")
      ->required();
  train->add_option("--out", *out, "Vocabulary file to write")->required();
  train->add_option("--k", options->k, "Branching factor")->capture_default_str();
  train->add_option("--levels", options->levels, "Tree depth")->capture_default_str();
  train->add_option("--seed", *seed, "Seed of the clustering")->capture_default_str();
  train->add_option("--features", *features, "ORB features per image")->capture_default_str();
  train->add_option("--max-images", *max_images, "Use at most N images, evenly spaced (0: all)");
  train->callback([=] { Train(*sources, *out, *options, *seed, *features, *max_images); });

  auto* info = cmd->add_subcommand("info", "Print a vocabulary file's parameters");
  auto file = std::make_shared<std::string>();
  info->add_option("file", *file, "Vocabulary file")->required();
  info->callback([file] { PrintVocabularyInfo(*file); });

  auto* score = cmd->add_subcommand("score", "Print the pairwise bag-of-words scores of images");
  auto score_vocabulary = std::make_shared<std::string>();
  auto score_images = std::make_shared<std::vector<std::string>>();
  score->add_option("--vocabulary", *score_vocabulary, "Vocabulary file (default: the shipped one)");
  score->add_option("images", *score_images, "Images, folders or list files")->required();
  score->callback([=] { Score(*score_vocabulary, *score_images); });
}

}  // namespace detslam::app
