#pragma once
// Options of the sim stage: the scene sections /hsm and /wind (docs/scene.md), read and
// validated by scene/ (src/scene/sim_sections.h); the engine never sees the JSON.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace treeanim {

// How the solver's per-step rates are obtained (docs/solver.md, "Stiffness").
enum class StiffnessMode : uint8_t {
  kPhysical,  // frequencies from branch geometry, Young's modulus and mass, converted per step
  kPerStep,   // the paper's alpha and k_d, used as given at every step
};

// What the solver stores its step state in (docs/solver.md, "Precision").
enum class Precision : uint8_t {
  kDouble,  // the reference: exact rigid motions, bit-stable golden files
  kFloat,   // half the memory traffic; ~1e-7 relative round-off, far below the step's error
};

// What the solver's particles are (docs/solver.md, "Particles").
enum class ParticleMode : uint8_t {
  kVertices,  // every mesh vertex is a particle (the paper's set-up)
  kSamples,   // a few particles per cluster stand for its vertices; the mesh is skinned per written frame
};

struct HsmOptions {
  // The scene's /hsm section.
  bool global_matching = true;           // paper Eq. 8 on/off
  StiffnessMode stiffness = StiffnessMode::kPhysical;
  double alpha = 0.5;                    // per-step local rate (kPerStep), [0, 1]
  double k_d = 0.02;                     // per-step global rate (kPerStep), [0, 1]
  double leaf_alpha = 1.0;               // per-step local rate of leaf clusters (both modes), [0, 1]
  double yield_strain = 0.01;            // bending strain beyond which a joint turns no further (the bar chain)
  double root_flexibility = 1.0;         // the root plate's turn per moment, in units of H / (E I) of the trunk's base
  double leaf_turn = 0.15;               // rad, a leaf's turn about its petiole in a 10 m/s wind across it (the bar chain)
  double youngs_modulus = 8e9;           // Pa, wood (the bar chain; with kPhysical the local rates too)
  double global_scale = 1.0;             // multiplies the limb stiffness of the global term (kPhysical)
  double max_frequency = 30;             // rad/s, highest frequency the solver resolves (kPhysical)
  double max_limb_frequency = 20;        // rad/s, highest limb (global) frequency (kPhysical)
  double min_limb_frequency = 1.25;      // rad/s, lowest limb (global) frequency (kPhysical)
  double damping_ratio = 0.1;            // structural damping ratio of the limb mode
  double leaf_detach_force = 0;          // N; 0 = leaves never detach
  Eigen::Vector3d gravity{0, -9.81, 0};  // m/s^2, acts on detached leaves only
  bool sleep = true;                     // resting islands in calm air skip all work
  double sleep_velocity = 1e-6;          // m/s, every vertex slower than this ...
  double sleep_distance = 1e-6;          // m, ... and closer than this to rest => island sleeps
  int rotation_iterations = 12;          // max iterations of the rotation extraction per step
  Precision precision = Precision::kDouble;  // storage of the step state
  ParticleMode particles = ParticleMode::kVertices;  // what the particles are
};

// One key of the wind time series; between keys the wind vector speed*direction and the gust
// amplitude are interpolated linearly, before the first / after the last key they are held.
struct WindKey {
  double time = 0;                       // s
  double speed = 0;                      // m/s, >= 0
  Eigen::Vector3d direction{1, 0, 0};    // unit vector (normalised when read)
  double gust = 0;                       // m/s, amplitude of the temporal gusting along the wind
};

// What blows outside a wind volume (docs/scene.md `wind.volume`).
enum class VolumeOutside : uint8_t {
  kKeys,  // the keyed mean wind (calm without keys)
  kCalm,  // still air
  kEdge,  // the nearest voxel's velocity: the volume held beyond its edge
};

// A velocity volume sequence from a fluid simulation (docs/scene.md `wind.volume`): it replaces
// the keyed mean wind inside it. Frame F of the sequence blows at scene time (F - first_frame) / fps.
struct VolumeOptions {
  std::filesystem::path path;            // the frame files: #### or %04d stands for the frame number; none: one frame for all time
  std::string grid = "vel";              // a vec3s grid, or the float grids grid.x, grid.y, grid.z
  double fps = 24;                       // volume frames per second
  long long first_frame = 1;             // the frame at scene time 0
  bool z_up = false;                     // a Z-up volume: (x, y, z) => (x, z, -y)
  VolumeOutside outside = VolumeOutside::kKeys;
  double units = 1;                      // m per volume unit, for positions and velocities alike
  double rotate = 0;                     // degrees about +Y, after the up axis is turned
  Eigen::Vector3d translate{0, 0, 0};    // m, where the volume's origin stands in the scene
};

struct WindOptions {
  // The scene's /wind section (keys or a CSV file, turbulence, drag).
  std::optional<std::filesystem::path> file;  // the CSV the keys came from, if any
  std::vector<WindKey> keys;                  // strictly increasing times; empty = calm
  double air_density = 1.225;                 // kg/m^3
  double branch_drag_coefficient = 1.2;       // Cd of a cylinder across the flow
  double leaf_drag_coefficient = 0.6;         // Cd of a leaf (flat plate, partly streamlined)
  double turbulence_intensity = 0.25;         // rms of each component / mean speed
  double turbulence_length = 4.0;             // m, length scale of the eddies
  double turbulence_frequency = 0.3;          // Hz, how fast the frozen field evolves in place
  int turbulence_modes = 8;                   // sinusoidal modes summed
  double gust_frequency = 0.2;                // Hz, typical gust rate
  uint64_t seed = 1;                          // turbulence and gusts
  std::optional<VolumeOptions> volume;        // a velocity volume replacing the mean wind inside it
  // A seamless loop (time.loop): > 0 makes the wind periodic with this period (s) from
  // loop_start (s); the keys must give the same wind at both ends (checked by scene/).
  double loop_period = 0;
  double loop_start = 0;
};

}  // namespace treeanim
