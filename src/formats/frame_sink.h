#pragma once
// FrameSink (docs/design.md): one output format, made by its factory (formats/sink_factories.h),
// whose row also names the files it creates, without a sink (its targets, checked before simulating).
// OutputSet calls begin() once, write() for every selected frame in order (on the sink's own
// writer thread), then finish() and, once every sink finished and every sink's targets are
// checked, commit(); or abort() at any point.
// Sinks never see solver internals, only the TreeModel, the BakeInfo and FrameData.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "files/staged_files.h"
#include "formats/outputs.h"
#include "output/output_options.h"
#include "tree/tree_model.h"

namespace treeanim {

// Which frames of the bake an output writes: frame_start, then every step-th frame.
struct FrameSelection {
  long long start = 0;  // first frame index of the bake
  long long count = 0;  // frames the bake pushes
  long long step = 1;   // write every step-th of them
  bool wants(long long frame) const { return (frame - start) % step == 0; }
  long long written() const { return (count + step - 1) / step; }
};

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  // The files named in the run's summary (a sequence by its first and last frame).
  virtual std::vector<SummaryFile> summary_paths() const = 0;
  // Opens the temporaries and writes what does not change over frames.
  virtual void begin() = 0;
  // Appends one selected frame. Throws OutputError naming the path.
  virtual void write(const FrameData& frame) = 0;
  // Completes and closes the temporaries.
  virtual void finish() {}
  // Throws OutputError when a final name no longer takes a file (StagedFiles::check).
  void check_targets() const { staged_.check(); }
  // Renames every temporary to its final name.
  void commit() { staged_.commit(); }
  // A line for the run's summary after finish() ("" for none), e.g. a fit's error.
  virtual std::string report() const { return ""; }
  // Closes and removes every temporary. Never throws.
  virtual void abort() noexcept { staged_.discard(); }

 protected:
  StagedFiles staged_;  // this sink's temporaries and their final names
};

}  // namespace treeanim
