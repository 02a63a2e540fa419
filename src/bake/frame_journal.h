#pragma once
// The frame journal of a checkpointed bake (docs/checkpoint.md): every frame handed to the
// outputs, as the outputs received it, appended in order. Checkpoints hold the state, not the
// frames before it; a resumed bake replays these into fresh outputs, so its files equal an
// uninterrupted bake's.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "formats/outputs.h"

namespace treeanim {

// What the records of a journal hold; a journal is reused only by the bake it was made for.
struct JournalLayout {
  std::string scene_hash;       // scene_hash() of the bake (bake/scene_hash.h)
  long long first_frame = 0;    // the first frame written (time.start, or --frames START)
  uint64_t vertices = 0;        // V: positions (and velocities) per record
  uint64_t leaves = 0;          // L: leaf flags per record
  bool velocities = false;      // records hold velocities (an output asked for them)
  uint64_t motion_clusters = 0; // C when records hold the clusters' motions (FrameData::cluster_motions), else 0
};

// A layout => the bytes of one record: frame, time, positions (and velocities), leaf flags
// (and cluster motions).
uint64_t journal_record_bytes(const JournalLayout& layout);

class FrameJournal {
 public:
  // Creates (truncates) the journal at `path`. Throws OutputError.
  static FrameJournal create(const std::filesystem::path& path, const JournalLayout& layout);
  // Opens the journal at `path`; throws InputError when it is missing, damaged or made for
  // another layout. Whole records only: a record cut short by a kill does not count.
  static FrameJournal open(const std::filesystem::path& path, const JournalLayout& layout);
  FrameJournal(FrameJournal&& other) noexcept;
  FrameJournal& operator=(FrameJournal&& other) noexcept;
  ~FrameJournal();

  long long size() const { return records_; }  // whole records
  // Record `index` (0 = first_frame) => the frame. Throws InputError on a short read or a
  // record of another frame.
  FrameData read(long long index);
  // Keeps the first `count` records; the next append() follows them. Throws OutputError.
  void truncate(long long count);
  // Appends one frame (positions, velocities and cluster motions when the layout has them, leaf flags).
  void append(const FrameData& frame);
  // Flushes the records to disk (before a checkpoint names them as written). Throws OutputError.
  void sync();

 private:
  FrameJournal(std::filesystem::path path, const JournalLayout& layout, std::FILE* file, long long records);
  uint64_t record_bytes() const { return journal_record_bytes(layout_); }
  std::filesystem::path path_;
  JournalLayout layout_;
  std::FILE* file_ = nullptr;
  long long records_ = 0;
};

}  // namespace treeanim
