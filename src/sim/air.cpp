// The air velocity each cluster feels (docs/solver.md, "Wind and forces"): sampled once per
// cluster and step, at the rest centre (a flying leaf: at its centre).
#include "sim/solver_step.h"

namespace treeanim {

void set_air_time(const WindField& wind, double t, AirSample& air) {
  air.base = wind.base(t);
  air.scale = wind.temporal_phases(t, air.sin_b, air.cos_b);
}

template <typename Real>
void sample_cluster_air(const SolverModel<Real>& model, const Attachment<Real>& attachment, const SimState& state,
                        StepScratch<Real>& scratch, size_t c) {
  const WindField& wind = model.wind;
  const AirSample& air = scratch.air;
  const int N = wind.mode_count();
  if (attachment.cluster_flying[c]) {
    double sin_a[kMaxModes], cos_a[kMaxModes];
    wind.spatial_phases(Eigen::Vector3d(attachment.cluster_rest_centre.col(c) + state.cluster_shift.col(c)), sin_a,
                        cos_a);
    const Eigen::Vector3d velocity = air.base + wind.turbulence(sin_a, cos_a, air.sin_b, air.cos_b, air.scale);
    scratch.cluster_air.row(c) = velocity.transpose().template cast<Real>();
  } else {
    const Eigen::Vector3d velocity =
        air.base + wind.turbulence(&model.cluster_turbulence_sin[c * N], &model.cluster_turbulence_cos[c * N],
                                   air.sin_b, air.cos_b, air.scale);
    scratch.cluster_air.row(c) = velocity.transpose().template cast<Real>();
  }
}

template void sample_cluster_air(const SolverModel<float>&, const Attachment<float>&, const SimState&,
                                 StepScratch<float>&, size_t);
template void sample_cluster_air(const SolverModel<double>&, const Attachment<double>&, const SimState&,
                                 StepScratch<double>&, size_t);

}  // namespace treeanim
