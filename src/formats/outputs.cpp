// OutputSet: checks every target before the simulation, then runs each sink on its own
// writer thread behind a bounded queue, so the bake takes about max(simulation, slowest sink).
#include "formats/outputs.h"

#include <sys/resource.h>
#include <unistd.h>

#include <memory>
#include <mutex>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "common/errors.h"
#include "common/input_files.h"
#include "common/ordered_worker.h"
#include "files/output_lock.h"
#include "files/staged_files.h"
#include "formats/frame_sink.h"
#include "formats/sink_factories.h"
#include "formats/vertex_normals.h"
#include "formats/output_estimate.h"
#include "output/output_formats.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

// Nice increment of writer threads (Linux: per thread). When the solver's OpenMP threads
// already use every core, a writer that preempts one of them stalls the whole team at its next
// barrier; niced, the writer runs in the gaps and only takes a core when its queue is full
// and the solver is waiting anyway.
constexpr int kWriterNice = 5;

// Frames a sink may lag behind the solver. Enough to absorb a slow frame (a compressed chunk,
// a page-cache flush) without holding much memory: 8 frames of the 211,812-vertex tree are 20 MB.
constexpr size_t kQueueFrames = 8;

fs::path resolve(const fs::path& path, const fs::path& out_dir) {
  return (path.is_relative() && !out_dir.empty() ? out_dir / path : path).lexically_normal();
}

// What names an output's files without its sink, which needs the tree's model: its options,
// path and frames.
struct OutputFiles {
  OutputOptions options;
  fs::path path;             // resolved against the out folder
  FrameSelection selection;  // the frames it writes
  SinkTargets* targets;      // its format's

  OutputFiles(const OutputOptions& output, const fs::path& out_dir, long long frame_start, long long frame_count)
      : options(output), path(resolve(output.path, out_dir)), selection{frame_start, frame_count, output.frame_step},
        targets(find_sink_targets(output.format->name)) {
    if (!targets) throw std::logic_error(std::string("OutputSet: no sink writes format ") + output.format->name);
  }

  // Calls `visit` with every file the output's sink will create, final names.
  void for_each(const TargetVisitor& visit) const { targets(options, path, selection, visit); }
};

// One sink and, from begin() on, its writer: a thread that writes the queued frames in order.
struct Worker {
  std::unique_ptr<FrameSink> sink;
  FrameSelection selection;
  fs::path first_path;  // for messages about failures that do not name a path themselves
  double estimated_bytes = 0;  // of the frames it will write (estimated_output_bytes)
  std::unique_ptr<OrderedWorker<std::shared_ptr<const FrameData>>> writer;

  Worker() = default;
  Worker(const Worker&) = delete;  // the writer's handler holds `this`
  Worker& operator=(const Worker&) = delete;

  void start_writer() {
    writer = std::make_unique<OrderedWorker<std::shared_ptr<const FrameData>>>(
        kQueueFrames, [] { setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kWriterNice); },  // best effort
        [this](const std::shared_ptr<const FrameData>& frame) {
          try {
            sink->write(*frame);
          } catch (const OutputError&) {
            throw;
          } catch (const std::exception& e) {  // named by the output's path
            throw OutputError(first_path.string() + ": " + e.what());
          }
        });
  }
};

// Frames every writer is done with, kept for the next ones: a frame's arrays (2.5 MB of
// positions on the 211,864-vertex tree) are allocated, and their pages touched, once for each
// frame in flight rather than once a frame. Shared with the frames' deleters, which may run on a
// writer's thread after the set is gone.
struct SpareFrames {
  std::mutex mutex;
  std::vector<FrameData> frames;
};

}  // namespace

struct OutputSet::Impl {
  const TreeModel& model;
  std::vector<OutputFiles> files;  // (outputs) what names each one's files
  std::vector<std::unique_ptr<Worker>> workers;
  std::shared_ptr<SpareFrames> spares = std::make_shared<SpareFrames>();
  bool velocities = false;
  bool normals = false;
  bool cluster_motions = false;
  std::vector<float> rest_normals;  // (V*3) fallback of vertices on no triangle of non-zero area
  bool leaf_flags = false;  // some output writes the leaves' attached flags
  bool done = false;  // finished or aborted
  OutputLocks locks;  // one per output, held from the checks to the end (files/output_lock.h)
  MadeFolders folders;  // made for the outputs: removed, when empty, if the bake fails

  // A failed bake's locks dropped and the folders it made removed (a lock file would keep one).
  void undo() noexcept {
    locks.release();
    folders.undo();
  }

  explicit Impl(const TreeModel& m) : model(m) {}
};

namespace {

// A file system's longest name (NAME_MAX of ext4, XFS, tmpfs, NFS), and what an output's own
// name may take of it: its lock ".NAME.lock" and temporaries ".NAME.tmp-PID" (and a USD
// layer's scratch beside them) add up to 32 bytes. A path the system takes is shorter than
// PATH_MAX with its terminating zero.
constexpr size_t kLockAndTemporaryBytes = 32, kMostPathBytes = 4096;
constexpr size_t kMostFolderNameBytes = 255, kMostFileNameBytes = 255 - kLockAndTemporaryBytes;

std::vector<OutputFiles> output_files(const std::vector<OutputOptions>& outputs, const fs::path& out_dir,
                                      long long frame_start, long long frame_count) {
  std::vector<OutputFiles> files;
  for (const OutputOptions& options : outputs) files.emplace_back(options, out_dir, frame_start, frame_count);
  return files;
}

}  // namespace

void check_output_limits(const std::vector<OutputOptions>& outputs, const TreeModel& model, const BakeInfo& info) {
  for (const OutputFiles& output : output_files(outputs, {}, info.frame_start, info.frame_count))
    find_sink_factory(output.options.format->name)(output.options, output.path, model, info);
}

std::string OutputTargets::real_folder(const fs::path& folder) {
  const auto [known, inserted] = real_folders_.try_emplace(folder.string());
  if (inserted) {
    std::error_code error;
    const fs::path absolute = folder.empty() ? cwd_ : folder.is_absolute() ? folder : cwd_ / folder;
    const fs::path real = fs::weakly_canonical(absolute, error);
    known->second = (error ? absolute.lexically_normal() : real).string();
    if (known->second.size() > 1 && known->second.back() == '/') known->second.pop_back();
  }
  return known->second;
}

std::string OutputTargets::identity(const fs::path& file) {
  const std::string folder = real_folder(file.parent_path());
  return (folder == "/" ? "" : folder) + "/" + file.filename().string();
}

// A sequence has a target per frame, so the checks run on strings: path comparisons per
// component cost ~20 us a target, a minute for a million-frame sequence.
void OutputTargets::add(const fs::path& target, const std::string& writer, const std::string& refused,
                        const std::string& expected, bool written) {
  // A name no file system takes (255 bytes), or one whose lock and temporaries would not fit:
  // refused here, before the bake, rather than met when the file is made.
  // On the string, as the rest of these checks: a sequence has a target per frame.
  const std::string& text = target.native();
  for (size_t start = 0; written;) {
    const size_t slash = text.find('/', start), end = slash == std::string::npos ? text.size() : slash;
    const bool file = end == text.size();
    if (end - start > (file ? kMostFileNameBytes : kMostFolderNameBytes))
      throw InputError(refused + (file ? "a file name of " : "a folder name of ") + std::to_string(end - start) +
                       " bytes: at most " +
                       (file ? std::to_string(kMostFileNameBytes) +
                                   ", a file system's 255 less the room of its lock and temporary files"
                             : std::to_string(kMostFolderNameBytes) + ", a file system's limit"));
    if (file) break;
    start = slash + 1;
  }
  if (written && text.size() + kLockAndTemporaryBytes >= kMostPathBytes)
    throw InputError(refused + "a path of " + std::to_string(text.size()) + " bytes: at most " +
                     std::to_string(kMostPathBytes - kLockAndTemporaryBytes - 1) +
                     ", the system's 4096 less the room of its lock and temporary files");
  OutputTarget resolved;
  try {
    resolved = resolve_output_target(target);
  } catch (const InputError& e) {
    if (!written) return;  // another's problem: it refuses its own
    throw InputError(refused + e.what());
  }
  const fs::path& file = resolved.file;
  const std::string absolute = identity(file);
  if (const auto lock = locks_.find(absolute); lock != locks_.end())
    throw InputError(refused + "writes " + file.string() + ", the lock file of " + lock->second);
  if (const auto owner = owned_.find(absolute); owner != owned_.end() && owner->second != writer)
    throw InputError(refused + "writes " + file.string() + ", the folder of " + owner->second);
  const auto [it, inserted] = writer_.emplace(absolute, writer);
  if (!inserted) throw InputError(refused + "writes " + file.string() + ", which " + it->second + " writes too");
  if (const auto other = in_folder_.find(absolute); other != in_folder_.end())
    throw InputError(refused + "writes " + file.string() + ", the folder " + other->second + " writes into");
  const std::string folder = absolute.substr(0, absolute.rfind('/'));
  if (const auto other = writer_.find(folder); other != writer_.end())
    throw InputError(refused + "writes into " + folder + ", which " + other->second + " writes as a file");
  if (const auto owner = owned_.find(folder); owner != owned_.end() && owner->second != writer)
    throw InputError(refused + "writes " + file.string() + ", in the folder of " + owner->second);
  in_folder_.emplace(folder, writer);
  if (!written) return;
  if (!resolved.kind.empty())
    throw InputError(refused + target.string() + (file == target ? " is " : " links to " + file.string() + ", ") +
                     resolved.kind + ", left untouched; " + expected);
  if (const std::string input = input_file_at(file); !input.empty())
    throw InputError(refused + "writes " + target.string() + ", which is " +
                     (input == target.string() ? "" : input + ", ") + "an input of this bake, left untouched");
  if (folders_.insert(folder).second) probes_.push_back(file);
}

void OutputTargets::add_outputs(const std::vector<OutputOptions>& outputs, const fs::path& out_dir,
                                long long frame_start, long long frame_count, const std::string& owner, bool written) {
  for (const OutputFiles& output : output_files(outputs, out_dir, frame_start, frame_count)) {
    const std::string& pointer = output.options.pointer;
    const std::string writer = owner.empty() ? pointer : pointer + " of " + owner;
    const std::string refused = output.options.where() + "/path" + (owner.empty() ? "" : " of " + owner) + ": ";
    bool first_frame = true;
    output.for_each([&](const fs::path& target, TargetKind kind) {
      add(target, writer, refused, "an output path must name a regular file or a new one", written);
      if (!written || (kind == TargetKind::kFrame && !std::exchange(first_frame, false))) return;
      // A lock beside each of its files, through any links, so that a link to another output's
      // file, another spelling of the same sequence, or another format's file of the same name
      // (a point cache's rest mesh, an OBJ sequence's) takes the same lock.
      const fs::path file = resolve_output_target(target).file;
      add_lock(lock_path(file), writer);
      lock_files_.push_back(file);
    });
  }
}

void OutputTargets::add_file(const fs::path& file, const std::string& writer, bool written) {
  add(file, writer, writer + ": ", "expected a regular file or a new one", written);
}

void OutputTargets::add_folder(const fs::path& folder, const std::string& writer) {
  const std::string absolute = real_folder(folder);
  if (const auto other = in_folder_.find(absolute); other != in_folder_.end() && other->second != writer)
    throw InputError(other->second + ": writes in " + folder.string() + ", the folder of " + writer);
  if (const auto other = writer_.find(absolute); other != writer_.end() && other->second != writer)
    throw InputError(other->second + ": writes " + folder.string() + ", the folder of " + writer);
  // It is made in its parent (a forest's tree's checkpoints in the forest's): a file there is refused.
  const std::string parent = absolute.substr(0, absolute.rfind('/'));
  if (const auto other = writer_.find(parent); other != writer_.end() && other->second != writer)
    throw InputError(other->second + ": writes " + folder.parent_path().string() + ", which holds the folder of " +
                     writer);
  in_folder_.emplace(parent, writer);
  owned_.emplace(absolute, writer);
  add_lock(lock_path(folder), writer);
}

void OutputTargets::add_lock(const fs::path& lock, const std::string& holder) {
  const std::string absolute = identity(lock);
  if (const auto other = writer_.find(absolute); other != writer_.end() && other->second != holder)
    throw InputError(other->second + ": writes " + lock.string() + ", the lock file of " + holder);
  locks_.emplace(absolute, holder);
}

void OutputTargets::probe(MadeFolders& made) const {
  for (const fs::path& file : probes_) check_writable_target(file, made);
}

OutputSet::OutputSet(const std::vector<OutputOptions>& outputs, const fs::path& out_dir, const TreeModel& model,
                     const BakeInfo& info, const fs::path& checkpoints)
    : impl_(std::make_unique<Impl>(model)) {
  impl_->files = output_files(outputs, out_dir, info.frame_start, info.frame_count);
  for (const OutputFiles& output : impl_->files) {
    const OutputOptions& options = output.options;
    auto worker = std::make_unique<Worker>();
    worker->sink = find_sink_factory(options.format->name)(options, output.path, model, info);  // the row OutputFiles found
    worker->selection = output.selection;
    const auto summary = worker->sink->summary_paths();
    worker->first_path = summary.empty() ? output.path : summary.front().path;
    worker->estimated_bytes = estimated_output_bytes(options, model.vertex_count(), model.triangle_count(),
                                                     model.cluster_count(), info.frame_count);
    impl_->velocities = impl_->velocities || options.velocities;
    impl_->normals = impl_->normals || options.normals;
    impl_->cluster_motions = impl_->cluster_motions || joint_per_cluster(options, model.cluster_count());
    impl_->leaf_flags = impl_->leaf_flags || options.format->leaf_flags;
    impl_->workers.push_back(std::move(worker));
  }
  try {
    OutputTargets targets;
    if (!checkpoints.empty()) targets.add_folder(checkpoints, "the checkpoints");
    targets.add_outputs(outputs, out_dir, info.frame_start, info.frame_count);
    targets.probe(impl_->folders);
    for (const fs::path& file : targets.lock_files()) impl_->locks.lock(file);
    // And the checkpoints' folder, before the bake reads or clears it: two bakes there would
    // write over each other's journal and checkpoints.
    if (!checkpoints.empty()) {
      std::error_code error;
      if (!checkpoints.parent_path().empty()) impl_->folders.make(checkpoints.parent_path(), error);
      impl_->locks.lock(checkpoints);
    }
  } catch (...) {
    impl_->undo();
    throw;
  }
  if (impl_->normals) impl_->rest_normals = rest_normals(model);
}

OutputSet::~OutputSet() {
  if (!impl_->done) abort();
}

bool OutputSet::wants_velocities() const { return impl_->velocities; }

bool OutputSet::wants_cluster_motions() const { return impl_->cluster_motions; }

void OutputSet::begin() {
  try {
    for (auto& worker : impl_->workers) worker->sink->begin();
  } catch (...) {
    abort();
    throw;
  }
  for (auto& worker : impl_->workers) worker->start_writer();
}

FrameData OutputSet::spare_frame() {
  const std::lock_guard lock(impl_->spares->mutex);
  if (impl_->spares->frames.empty()) return {};
  FrameData frame = std::move(impl_->spares->frames.back());
  impl_->spares->frames.pop_back();
  return frame;
}

void OutputSet::push(FrameData frame) {
  const size_t n = 3 * impl_->model.vertex_count();
  const size_t motions = frame.cluster_motions.size();
  if (frame.positions.size() != n || (impl_->velocities && frame.velocities.size() != n) ||
      (motions != 0 && motions != 7 * impl_->model.cluster_count()) ||
      (impl_->leaf_flags && frame.leaf_attached.size() != impl_->model.leaf_count()))
    throw std::logic_error("OutputSet::push: frame " + std::to_string(frame.frame) +
                           " does not match the model (positions " + std::to_string(frame.positions.size()) +
                           ", velocities " + std::to_string(frame.velocities.size()) + ", leaf flags " +
                           std::to_string(frame.leaf_attached.size()) + ", cluster motions " + std::to_string(motions) +
                           ")");
  // Once per frame for every output that carries them, on the caller's thread: the writers
  // share the frame read-only.
  if (impl_->normals) vertex_normals(impl_->model, frame.positions.data(), impl_->rest_normals, frame.normals);
  // The last writer done with it hands it back (at most what the queues hold and one more).
  const std::shared_ptr<const FrameData> shared(
      new FrameData(std::move(frame)), [spares = impl_->spares, limit = kQueueFrames + 1](FrameData* done) noexcept {
        const std::unique_ptr<FrameData> owned(done);
        try {
          const std::lock_guard lock(spares->mutex);
          if (spares->frames.size() < limit) spares->frames.push_back(std::move(*owned));
        } catch (...) {  // the lock or the room failed: it is freed
        }
      });
  for (auto& worker : impl_->workers)
    if (worker->selection.wants(shared->frame)) worker->writer->push(shared);
}

bool OutputSet::finish(const std::function<bool()>& stop) {
  try {
    // Each writer drains its queue (all at once, on their threads); the first failure in
    // the outputs' order is the one reported.
    for (auto& worker : impl_->workers) worker->writer->close();
    // Every file complete, and every target still one a file may replace, before any is
    // renamed: a failure here still leaves no output.
    for (auto& worker : impl_->workers) worker->sink->finish();
    if (stop()) {
      abort();
      return false;
    }
    for (auto& worker : impl_->workers) worker->sink->check_targets();
    for (auto& worker : impl_->workers) worker->sink->commit();
  } catch (...) {
    abort();
    throw;
  }
  impl_->locks.release();
  impl_->done = true;
  return true;
}

void OutputSet::abort() noexcept {
  for (auto& worker : impl_->workers) {
    if (worker->writer) worker->writer->stop();
    worker->sink->abort();
  }
  impl_->undo();
  impl_->done = true;
}

std::vector<std::pair<fs::path, std::string>> OutputSet::reports() const {
  std::vector<std::pair<fs::path, std::string>> reports;
  for (const auto& worker : impl_->workers)
    if (std::string line = worker->sink->report(); !line.empty()) reports.emplace_back(worker->first_path, line);
  return reports;
}

std::vector<std::pair<fs::path, double>> OutputSet::estimated_bytes() const {
  std::vector<std::pair<fs::path, double>> bytes;
  for (const auto& worker : impl_->workers) bytes.emplace_back(worker->first_path, worker->estimated_bytes);
  return bytes;
}

std::vector<fs::path> OutputSet::files(size_t k) const {
  std::vector<fs::path> files;
  impl_->files.at(k).for_each([&](const fs::path& file, TargetKind) { files.push_back(file); });
  return files;
}

std::vector<SummaryFile> OutputSet::final_paths() const {
  std::vector<SummaryFile> paths;
  for (const auto& worker : impl_->workers)
    for (const SummaryFile& file : worker->sink->summary_paths()) paths.push_back(file);
  return paths;
}

}  // namespace treeanim
