// Why images did not register: the probable causes eval can see in the images themselves, next
// to the others of the set: under-exposure and blur (image statistics), few features (COLMAP's
// extraction log), a static background that was not masked, too little overlap with the
// neighbours in capture order.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "eval/chroma_key.h"

namespace rigc::eval {

// One image's statistics, over its mask when it has one.
struct ImageStatistics {
  double sharpness = 0;  // variance of the Laplacian of the grey image (codes^2)
  double mean_luma = 0;  // mean sRGB luma, 0..1
  double p99_luma = 0;   // 99th percentile of the luma
};
ImageStatistics image_statistics(const KeyImage& image, const std::vector<std::uint8_t>& mask);

// What diagnose_unregistered looks at.
struct DiagnosisInputs {
  std::vector<std::string> order;                // every image, in capture order
  std::set<std::string> registered;              // the registered ones
  std::map<std::string, ImageStatistics> stats;  // by image name
  std::map<std::string, double> features;        // COLMAP's features by image name
  bool masked = false;                           // COLMAP had object masks
  double still_fraction = 0;                     // the share of pixels still across the set
};

// For each unregistered image, its probable causes (at least one), by image name.
std::map<std::string, std::vector<std::string>> diagnose_unregistered(const DiagnosisInputs& in);

// COLMAP's feature count of each image from a feature_extractor log ("Name:" then "Features:").
std::map<std::string, double> features_by_image(const std::string& log_text);

}  // namespace rigc::eval
