#pragma once
// Federated averaging (McMahan et al. 2017; paper "Problem Formulation"):
//   theta^{r+1} = sum_k (n_k / n) theta_k^r,  n = sum_k n_k,
// over the WHOLE model: parameters and batch-norm running statistics.

#include <cstdint>
#include <vector>

#include "palcas_core/learning/model_blob.h"

namespace palcas {

/// Default ceiling for one client's sample count: more than 1e9 samples in one round is
/// implausible for an RSU (10 Hz x 100 CAVs would need ~12 days) and hints at a bug.
constexpr uint64_t FEDAVG_MAX_SAMPLES_DEFAULT = 1000000000ULL;

/// Sample-weighted average of `models`, accumulated in double. Pure: never changes its
/// inputs. Throws std::invalid_argument naming the index and the value when: models is
/// empty; sample_counts.size() != models.size(); a model's layout id or checksum differs
/// from model 0's, or its checksum does not match its own layout id; value counts differ;
/// a value is not finite; n_k == 0; n_k > max_samples. The result is finite.
ModelBlob fedAverage(const std::vector<ModelBlob>& models,
                     const std::vector<uint64_t>& sample_counts,
                     uint64_t max_samples = FEDAVG_MAX_SAMPLES_DEFAULT);

/// Coordinate-wise median of `models` (the mean of the two middle values for an even count).
/// Same checks as fedAverage but no sample counts. Pure; the result is finite.
ModelBlob coordinateMedian(const std::vector<ModelBlob>& models);

/// Coordinate-wise mean after dropping floor(trim_fraction * K) of the largest and as many
/// of the smallest values of each coordinate (K = models.size()). trim_fraction in [0, 0.5);
/// otherwise the same checks as fedAverage. Pure; the result is finite.
ModelBlob trimmedMean(const std::vector<ModelBlob>& models, double trim_fraction);

}  // namespace palcas
