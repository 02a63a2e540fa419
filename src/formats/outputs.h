#pragma once
// OutputSet, what the bake writes through: every output of a bake, each sink on its own
// writer thread behind a bounded queue, so writing never stalls the solver. Each sink writes to
// a temporary name beside its target and renames it when complete; abort() removes every
// temporary.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "files/staged_files.h"
#include "output/output_options.h"
#include "sim/sim_options.h"
#include "tree/surface_materials.h"
#include "tree/tree_model.h"
#include "tree/tree_placement.h"

namespace treeanim {

// What the sinks record about the bake besides the frames.
struct BakeInfo {
  std::string scene_json;      // resolved scene (defaults filled in)
  std::string generator;       // "treeanim <version>"
  double fps = 24;
  long long frame_start = 0;   // first frame index written
  long long frame_count = 0;   // frames the bake will hand to push()
  int substeps = 1;
  uint64_t seed = 0;
  // A seamless loop of the whole bake (time.loop): the first frame comes again at
  // loop_end_time (s), so animations add a closing key there.
  bool loop = false;
  double loop_end_time = 0;
  // The mesh's look: materials by TriangleMaterial, and (V*3) linear colour factors per vertex
  // (tree/surface_materials.h; empty: no vertex colours).
  std::array<SurfaceMaterial, kMaterialCount> materials = surface_materials(TreeOptions{});
  std::vector<float> vertex_colors;
  WindOptions wind;            // the scene's wind when an html page plots it at the tree, else the default
  TreePlacement placement;     // where the tree stands in that wind; identity for a lone tree
};

// One simulated frame, converted to float for output.
struct FrameData {
  long long frame = 0;                 // absolute frame index
  double time = 0;                     // s
  std::vector<float> positions;        // (V*3) m
  std::vector<float> velocities;       // (V*3) m/s; empty unless some output asked for them
  std::vector<float> normals;          // (V*3) unit; filled by OutputSet::push when an output wants them
  std::vector<uint8_t> leaf_attached;  // (L)
  // (C*7) each cluster's rigid motion x = R x0 + t as the solver moved it: the quaternion of R
  // (x, y, z, w), then t (m). Only from a bake on samples (hsm.particles "samples", whose mesh is
  // placed from these) when an output asks (OutputSet::wants_cluster_motions); else empty.
  std::vector<float> cluster_motions;
};

// The files a bake will write, looked at before any is: each written by one writer only, and
// absent or a regular file after its symbolic links (InputError, nothing created); then, by
// probe(), every folder able to take a file. OutputSet checks its outputs so; a forest checks
// every tree's outputs, parts and manifest before it grows the first, so that a later tree's
// target cannot fail the forest after earlier trees were written.
// Each output's own limits as a bake meets them before it opens a file (a VAT's texture size,
// a preview page's max_mib, glTF's 4 GiB): its writer built for this model and dropped. Throws
// the InputError or OutputError the bake would.
void check_output_limits(const std::vector<OutputOptions>& outputs, const TreeModel& model, const BakeInfo& info);

class OutputTargets {
 public:
  // The outputs' files for frame_count frames from frame_start, resolved against out_dir, named
  // in messages by `owner` and the output's pointer (owner "" for a lone tree). `written` false:
  // a writer that does not write now (a forest tree of another shard, or complete), whose
  // files only no other writer may take.
  void add_outputs(const std::vector<OutputOptions>& outputs, const std::filesystem::path& out_dir,
                   long long frame_start, long long frame_count, const std::string& owner = "", bool written = true);
  // One more file, written by `writer` (e.g. "the forest's manifest").
  void add_file(const std::filesystem::path& file, const std::string& writer, bool written = true);
  // A folder whose files only `writer` writes (a bake's checkpoints: it removes what it does not
  // read back), refused to every other writer's files, added before or after it.
  void add_folder(const std::filesystem::path& folder, const std::string& writer);
  // The lock file that keeps other bakes off `holder`'s files (files/output_lock.h), which no
  // writer may take: its output would be unlinked as the lock is released.
  void add_lock(const std::filesystem::path& lock, const std::string& holder);
  // The file each written output's lock stands beside (files/output_lock.h), in the order added.
  const std::vector<std::filesystem::path>& lock_files() const { return lock_files_; }
  // Each folder made when missing (into `made`, which the caller undoes when it gives up: a
  // folder another process may be writing into is not removed while it bakes) and a file
  // created and removed in it. Throws OutputError naming the path.
  void probe(MadeFolders& made) const;

 private:
  // `target`, written by `writer`, refused in messages that start with `refused` and end, for a
  // folder or another file that is not a regular one, with `expected` => registered.
  void add(const std::filesystem::path& target, const std::string& writer, const std::string& refused,
           const std::string& expected, bool written);

  // A folder => its absolute path with its links followed, as the system resolves it (the part
  // that exists; the rest lexically), once per folder: another spelling of a folder, or a link
  // to it, is the same folder.
  std::string real_folder(const std::filesystem::path& folder);
  // A file => real_folder of its folder, then its name: the string the checks compare.
  std::string identity(const std::filesystem::path& file);

  std::filesystem::path cwd_ = std::filesystem::current_path();
  std::unordered_map<std::string, std::string> real_folders_;  // a folder as given => real_folder
  std::unordered_map<std::string, std::string> writer_;  // absolute file written => its writer
  std::unordered_map<std::string, std::string> in_folder_;  // absolute folder => a writer of a file in it
  std::unordered_map<std::string, std::string> owned_;      // absolute folder => its only writer
  std::unordered_map<std::string, std::string> locks_;      // absolute lock file => what it locks
  std::vector<std::filesystem::path> lock_files_;            // see lock_files()
  std::unordered_set<std::string> folders_;              // absolute folders seen
  std::vector<std::filesystem::path> probes_;            // the first file of each folder
};

// A line of the run's summary: one file, or a sequence of `files` frames' files from `path` to
// `last` (a sequence of one frame is one file).
struct SummaryFile {
  std::filesystem::path path;
  long long files = 1;
  std::filesystem::path last = {};
};

class OutputSet {
 public:
  // Resolves relative paths against out_dir (when not empty), checks every target (folder
  // exists or can be made, writable, format limits such as 4 GiB GLB) and locks each output
  // against other bakes (files/output_lock.h) before simulation; finish() and abort() unlock. The
  // options are as the scene reader checked them. Throws InputError for a target no output may
  // write (a directory, one written twice), OutputError naming the path for unwritable
  // targets, a GLB past 4 GiB and an output another bake holds. `checkpoints`: the folder of the
  // bake's checkpoints (empty: none), where no output may write, locked as the outputs are.
  OutputSet(const std::vector<OutputOptions>& outputs, const std::filesystem::path& out_dir,
            const TreeModel& model, const BakeInfo& info, const std::filesystem::path& checkpoints = {});
  ~OutputSet();  // abort()s when finish() was not reached
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  bool wants_velocities() const;
  // Some output takes a joint per cluster (a skinned one without merged limbs): a bake on
  // samples hands it the clusters' own motions, FrameData::cluster_motions.
  bool wants_cluster_motions() const;
  // Opens temporaries, writes headers and the rest mesh; starts each sink's writer thread.
  void begin();
  // A frame to fill for push(): one that every writer is done with when there is one, its
  // arrays still allocated (a bake's frames all have the same sizes), else an empty one.
  FrameData spare_frame();
  // Queues a frame (blocks while the queue is full). Rethrows a writer failure as OutputError.
  void push(FrameData frame);
  // Drains the queue, closes files, renames temporaries to their final names; unless
  // `stop` says, once every file is complete, that the bake was interrupted meanwhile (the
  // files can take long: a skin's fit, a page): then aborts, as abort(), and returns false.
  bool finish(const std::function<bool()>& stop = [] { return false; });
  // Stops the writer and removes every temporary. Never throws.
  void abort() noexcept;
  // What the run's summary names: each file, or each sequence's first and last.
  std::vector<SummaryFile> final_paths() const;
  // Every file of output k, in the order of its sink (a sequence: each frame's file and the rest mesh).
  std::vector<std::filesystem::path> files(size_t k) const;
  // Each output's first file and the bytes of the frames it will write (estimated_output_bytes).
  std::vector<std::pair<std::filesystem::path, double>> estimated_bytes() const;
  // After finish(): what outputs have to say besides their paths (a fit's error), by output path.
  std::vector<std::pair<std::filesystem::path, std::string>> reports() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace treeanim
