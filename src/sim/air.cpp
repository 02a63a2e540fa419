// The air velocity each cluster feels (docs/solver.md, "Wind and forces"): sampled once per
// cluster and step, at the rest centre (a flying leaf: at its centre).
#include "sim/solver_step.h"

namespace treeanim {

void set_air_time(const WindField& wind, double t, double step, AirSample& air) { wind.sample_time(t, step, air); }

template <typename Real>
void sample_cluster_air(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                        StepScratch<Real>& scratch, size_t c) {
  const WindField& wind = model.wind;
  Eigen::Vector3d velocity;
  if (attachment.cluster_flying[c]) {
    double sin_a[kMaxPhases], cos_a[kMaxPhases];
    wind.spatial_phases(Eigen::Vector3d(attachment.cluster_rest_centre.col(c) + state.cluster_shift.col(c)), sin_a,
                        cos_a);
    velocity = wind.velocity(sin_a, cos_a, scratch.air);
  } else {
    const size_t P = size_t(wind.phase_count());
    velocity = wind.velocity(&model.cluster_phase_sin[c * P], &model.cluster_phase_cos[c * P], scratch.air);
  }
  scratch.cluster_air.row(c) = velocity.transpose().template cast<Real>();
}

template void sample_cluster_air(const SolverModel<float>&, const Attachment<float>&, const SimState&,
                                 StepScratch<float>&, size_t);
template void sample_cluster_air(const SolverModel<double>&, const Attachment<double>&, const SimState&,
                                 StepScratch<double>&, size_t);

}  // namespace treeanim
