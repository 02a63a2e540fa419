// The air velocity each cluster feels (docs/solver.md, "Wind and forces"): sampled once per
// cluster and step, at the rest centre (a flying leaf: at its centre).
#include <algorithm>

#include "sim/solver_step.h"

namespace treeanim {

namespace {

// The volume's frames around t => scratch.volume_at_rest holds their velocities at the rest
// centres; a frame already sampled is kept, so each frame is sampled once per bake.
template <typename Real>
void sample_volume_at_rest(const SolverModel<Real>& model, const WindVolume& volume, double t,
                           StepScratch<Real>& scratch) {
  scratch.volume = volume.at(t);
  for (int j = 0; j < 2; ++j) {
    const long long wanted = scratch.volume.number[j];
    if (!scratch.volume.frame[j] || scratch.volume_sampled[j] == wanted) continue;
    const int other = 1 - j;
    if (scratch.volume_sampled[other] == wanted) {  // the later frame became the earlier one
      std::swap(scratch.volume_at_rest[j], scratch.volume_at_rest[other]);
      std::swap(scratch.volume_inside[j], scratch.volume_inside[other]);
      std::swap(scratch.volume_sampled[j], scratch.volume_sampled[other]);
      continue;
    }
    volume.sample(*scratch.volume.frame[j], model.all_attached.cluster_rest_centre, scratch.volume_at_rest[j],
                  scratch.volume_inside[j]);
    scratch.volume_sampled[j] = wanted;
  }
}

}  // namespace

template <typename Real>
void set_air_time(const SolverModel<Real>& model, double t, StepScratch<Real>& scratch) {
  model.wind.sample_time(t, model.h, scratch.air);
  if (const WindVolume* volume = model.wind.volume()) sample_volume_at_rest(model, *volume, t, scratch);
}

template <typename Real>
void sample_cluster_air(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                        StepScratch<Real>& scratch, size_t c) {
  const WindField& wind = model.wind;
  const WindVolume* volume = wind.volume();
  Eigen::Vector3d velocity;
  if (attachment.cluster_flying[c]) {
    const Eigen::Vector3d centre = attachment.cluster_rest_centre.col(c) + state.cluster_shift.col(c);
    double sin_a[kMaxPhases], cos_a[kMaxPhases];
    wind.spatial_phases(centre, sin_a, cos_a);
    velocity = volume ? wind.velocity(sin_a, cos_a, scratch.air, volume->mean(scratch.volume, centre, scratch.air.mean))
                      : wind.velocity(sin_a, cos_a, scratch.air);
  } else {
    const size_t P = size_t(wind.phase_count());
    const double* sin_a = &model.cluster_phase_sin[c * P];
    const double* cos_a = &model.cluster_phase_cos[c * P];
    if (volume) {
      const bool later = scratch.volume.frame[1] != nullptr;
      const Eigen::Vector3d mean = volume->blend(
          scratch.volume_inside[0][c], scratch.volume_at_rest[0].col(c), later && scratch.volume_inside[1][c],
          later ? Eigen::Vector3d(scratch.volume_at_rest[1].col(c)) : Eigen::Vector3d::Zero(), scratch.volume.weight,
          scratch.air.mean);
      velocity = wind.velocity(sin_a, cos_a, scratch.air, mean);
    } else {
      velocity = wind.velocity(sin_a, cos_a, scratch.air);
    }
  }
  scratch.cluster_air.row(c) = velocity.transpose().template cast<Real>();
}

template <typename Real>
void AirLanes<Real>::add(uint32_t c) {
  if (model_.wind.volume() || attachment_.cluster_flying[c])
    return sample_cluster_air(model_, attachment_, state_, scratch_, c);
  lane_[count_++] = c;
  if (count_ == 4) flush();
}

template <typename Real>
void AirLanes<Real>::flush() {
  if (count_ == 0) return;
  const size_t P = size_t(model_.wind.phase_count());
  const double* sin_a[4];
  const double* cos_a[4];
  for (size_t l = 0; l < 4; ++l) {
    const uint32_t c = lane_[std::min(l, count_ - 1)];  // lanes past the last repeat it
    sin_a[l] = &model_.cluster_phase_sin[c * P], cos_a[l] = &model_.cluster_phase_cos[c * P];
  }
  double v[3][4];
  model_.wind.velocities(sin_a, cos_a, scratch_.air, v);
  for (size_t l = 0; l < count_; ++l)
    for (int i = 0; i < 3; ++i) scratch_.cluster_air(lane_[l], i) = static_cast<Real>(v[i][l]);
  count_ = 0;
}

template void set_air_time(const SolverModel<float>&, double, StepScratch<float>&);
template void set_air_time(const SolverModel<double>&, double, StepScratch<double>&);
template void sample_cluster_air(const SolverModel<float>&, const Attachment<float>&, const SimState&,
                                 StepScratch<float>&, size_t);
template void sample_cluster_air(const SolverModel<double>&, const Attachment<double>&, const SimState&,
                                 StepScratch<double>&, size_t);
template class AirLanes<float>;
template class AirLanes<double>;

}  // namespace treeanim
