#include "palcas_core/learning/fedavg.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "palcas_core/common/checks.h"
#include "palcas_core/learning/model_blob.h"
#include "palcas_core/learning/nn/serialization.h"

namespace palcas {

namespace {

void checkModel(const ModelBlob& m, size_t k, const ModelBlob& first) {
  const BlobCheck check = checkModelBlob(m, &first, "model 0");
  common::require(check.ok(), "fedAverage: model ", k, ": ", check.detail);
}

}  // namespace

ModelBlob fedAverage(const std::vector<ModelBlob>& models,
                     const std::vector<uint64_t>& sample_counts, uint64_t max_samples) {
  using common::require;
  require(!models.empty(), "fedAverage: no models to average");
  require(sample_counts.size() == models.size(), "fedAverage: ", models.size(), " models but ",
          sample_counts.size(), " sample counts");
  double total = 0.0;
  for (size_t k = 0; k < models.size(); ++k) {
    const uint64_t n_k = sample_counts[k];
    require(n_k != 0, "fedAverage: model ", k, " has sample count 0");
    require(n_k <= max_samples, "fedAverage: model ", k, " has sample count ", n_k,
            " > the plausible maximum ", max_samples);
    checkModel(models[k], k, models.front());
    total += static_cast<double>(n_k);
  }
  // theta = sum_k (n_k / n) theta_k, accumulated in double, model by model (streams
  // through memory once per model).
  const auto size = static_cast<Eigen::Index>(models.front().values.size());
  Eigen::VectorXd acc = Eigen::VectorXd::Zero(size);
  for (size_t k = 0; k < models.size(); ++k) {
    const double w = static_cast<double>(sample_counts[k]) / total;
    acc += w * Eigen::Map<const Eigen::VectorXf>(models[k].values.data(), size).cast<double>();
  }
  ModelBlob out;
  out.layout_id = models.front().layout_id;
  out.layout_checksum = models.front().layout_checksum;
  out.values.resize(static_cast<size_t>(size));
  Eigen::Map<Eigen::VectorXf>(out.values.data(), size) = acc.cast<float>();
  return out;
}

namespace {

// Per coordinate: the K values sorted, reduced by `reduce`; models validated first.
template <typename Reduce>
ModelBlob perCoordinate(const std::vector<ModelBlob>& models, const char* who, Reduce reduce) {
  if (models.empty()) throw std::invalid_argument(std::string(who) + ": no models");
  for (size_t k = 0; k < models.size(); ++k) checkModel(models[k], k, models.front());
  const size_t size = models.front().values.size();
  ModelBlob out;
  out.layout_id = models.front().layout_id;
  out.layout_checksum = models.front().layout_checksum;
  out.values.resize(size);
  std::vector<float> column(models.size());
  for (size_t i = 0; i < size; ++i) {
    for (size_t k = 0; k < models.size(); ++k) column[k] = models[k].values[i];
    std::sort(column.begin(), column.end());
    out.values[i] = reduce(column);
  }
  return out;
}

}  // namespace

ModelBlob coordinateMedian(const std::vector<ModelBlob>& models) {
  return perCoordinate(models, "coordinateMedian", [](const std::vector<float>& c) {
    const size_t n = c.size();
    return n % 2 ? c[n / 2] : static_cast<float>(0.5 * (double(c[n / 2 - 1]) + double(c[n / 2])));
  });
}

ModelBlob trimmedMean(const std::vector<ModelBlob>& models, double trim_fraction) {
  if (!(trim_fraction >= 0.0 && trim_fraction < 0.5))
    throw std::invalid_argument("trimmedMean: trim_fraction " + std::to_string(trim_fraction) +
                                " is outside [0, 0.5)");
  const size_t drop = static_cast<size_t>(std::floor(trim_fraction * static_cast<double>(models.size())));
  return perCoordinate(models, "trimmedMean", [drop](const std::vector<float>& c) {
    double sum = 0.0;
    for (size_t k = drop; k < c.size() - drop; ++k) sum += c[k];
    return static_cast<float>(sum / static_cast<double>(c.size() - 2 * drop));
  });
}

}  // namespace palcas
