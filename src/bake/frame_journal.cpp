// Journal layout (little-endian, docs/checkpoint.md): a 96-byte header, magic "TAJOURN2",
// u64 record bytes, i64 first frame, u64 V, u64 L, u8 velocities, padding, u64 motion clusters
// C, padding, then the FNV-1a scene hash as 32 bytes of text, zero-padded; then fixed-size records: i64 frame,
// f64 time, f32 positions (V x 3), f32 velocities (V x 3, when recorded), u8 leaf flags (L),
// f32 cluster motions (C x 7, when recorded), u32 zlib crc32 of the record's bytes before it.
#include "bake/frame_journal.h"

#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/errors.h"
#include "files/io_failure.h"
#include "files/staged_files.h"

namespace treeanim {

namespace fs = std::filesystem;

namespace {

static_assert(std::endian::native == std::endian::little, "the journal is written in host order");

constexpr char kMagic[8] = {'T', 'A', 'J', 'O', 'U', 'R', 'N', '2'};
constexpr size_t kHeaderBytes = 96;
constexpr size_t kHashBytes = 32;

std::vector<unsigned char> header_bytes(const JournalLayout& layout, uint64_t record_bytes) {
  std::vector<unsigned char> header(kHeaderBytes, 0);
  const int64_t first = layout.first_frame;
  std::memcpy(&header[0], kMagic, 8);
  std::memcpy(&header[8], &record_bytes, 8);
  std::memcpy(&header[16], &first, 8);
  std::memcpy(&header[24], &layout.vertices, 8);
  std::memcpy(&header[32], &layout.leaves, 8);
  header[40] = layout.velocities ? 1 : 0;
  std::memcpy(&header[48], &layout.motion_clusters, 8);
  std::memcpy(&header[64], layout.scene_hash.data(), std::min(layout.scene_hash.size(), kHashBytes));
  return header;
}

}  // namespace

FrameJournal::FrameJournal(fs::path path, const JournalLayout& layout, std::FILE* file, long long records)
    : path_(std::move(path)), layout_(layout), file_(file), records_(records) {}

FrameJournal::FrameJournal(FrameJournal&& other) noexcept
    : path_(std::move(other.path_)), layout_(other.layout_), file_(other.file_), records_(other.records_) {
  other.file_ = nullptr;
}

FrameJournal& FrameJournal::operator=(FrameJournal&& other) noexcept {
  std::swap(path_, other.path_);
  std::swap(layout_, other.layout_);
  std::swap(file_, other.file_);
  std::swap(records_, other.records_);
  return *this;
}

FrameJournal::~FrameJournal() {
  if (file_) std::fclose(file_);
}

uint64_t journal_record_bytes(const JournalLayout& layout) {
  return 16 + 12 * layout.vertices * (layout.velocities ? 2 : 1) + layout.leaves + 28 * layout.motion_clusters + 4;
}

namespace {

// A record's parts in file order, read into `frame` (FrameData) or written from it (const
// FrameData), each folded into the record's crc32 => whether every transfer succeeded.
template <typename Frame, typename Number, typename Transfer>
bool transfer_record(Transfer transfer, Number& number, Frame& frame, bool velocities, uint32_t& crc) {
  uLong sum = crc32(0L, Z_NULL, 0);
  auto part = [&](auto* data, size_t bytes) {
    if (!transfer(data, bytes)) return false;
    const auto* first = reinterpret_cast<const Bytef*>(data);
    for (size_t done = 0; done < bytes;) {  // crc32 takes a uInt length
      const size_t chunk = std::min<size_t>(bytes - done, 1u << 30);
      sum = crc32(sum, first + done, static_cast<uInt>(chunk));
      done += chunk;
    }
    return true;
  };
  const bool ok = part(&number, 8) && part(&frame.time, 8) && part(frame.positions.data(), 4 * frame.positions.size()) &&
                  (!velocities || part(frame.velocities.data(), 4 * frame.velocities.size())) &&
                  part(frame.leaf_attached.data(), frame.leaf_attached.size()) &&
                  part(frame.cluster_motions.data(), 4 * frame.cluster_motions.size());
  crc = static_cast<uint32_t>(sum);
  return ok;
}

}  // namespace

FrameJournal FrameJournal::create(const fs::path& path, const JournalLayout& layout) {
  std::error_code error;
  fs::create_directories(path.parent_path(), error);
  if (error)  // a read-only disk: the open below would only say "No such file or directory"
    throw OutputError(path.string() + ": cannot create the folder of the frame journal: " + error.message());
  if (const std::string kind = resolve_output_target(path).kind; !kind.empty())  // "w+b" would take a FIFO
    throw OutputError(path.string() + ": " + kind + " stands where the bake writes its frame journal; left untouched");
  std::FILE* file = std::fopen(path.c_str(), "w+b");
  if (!file) throw OutputError(io_failure(path, "cannot create the frame journal"));
  FrameJournal journal(path, layout, file, 0);
  const std::vector<unsigned char> header = header_bytes(layout, journal.record_bytes());
  if (std::fwrite(header.data(), 1, header.size(), file) != header.size())
    throw OutputError(io_failure(path, "cannot write the frame journal"));
  return journal;
}

FrameJournal FrameJournal::open(const fs::path& path, const JournalLayout& layout) {
  // A FIFO or a device would block the open, or read for ever.
  if (std::error_code error; fs::exists(path, error) && !fs::is_regular_file(path, error))
    throw InputError(path.string() + ": the frame journal is not a regular file");
  std::FILE* file = std::fopen(path.c_str(), "r+b");
  // A journal the bake may not write cannot be continued; baking from the start instead would
  // redo every frame it holds, where the user asked to resume.
  if (!file && (errno == EACCES || errno == EPERM || errno == EROFS))
    throw OutputError(io_failure(path, "cannot open the frame journal to continue it") +
                      " (--resume appends to it: its folder must be writable)");
  if (!file) throw InputError(io_failure(path, "cannot open the frame journal"));
  FrameJournal journal(path, layout, file, 0);
  std::vector<unsigned char> header(kHeaderBytes);
  if (std::fread(header.data(), 1, header.size(), file) != header.size() ||
      header != header_bytes(layout, journal.record_bytes()))
    throw InputError(path.string() + ": the frame journal is damaged or belongs to another bake (scene, frames or outputs)");
  if (std::fseek(file, 0, SEEK_END) != 0) throw InputError(io_failure(path, "cannot read the frame journal"));
  const long end = std::ftell(file);
  journal.records_ = static_cast<long long>((uint64_t(end) - kHeaderBytes) / journal.record_bytes());
  return journal;
}

FrameData FrameJournal::read(long long index) {
  FrameData frame;
  const size_t n = 3 * layout_.vertices;
  frame.positions.resize(n);
  if (layout_.velocities) frame.velocities.resize(n);
  frame.leaf_attached.resize(layout_.leaves);
  const size_t motions = 7 * layout_.motion_clusters;
  frame.cluster_motions.resize(motions);
  int64_t number = 0;
  uint32_t crc = 0, stored = 0;
  auto read = [&](void* data, size_t bytes) { return std::fread(data, 1, bytes, file_) == bytes; };
  const bool ok =
      index < records_ && std::fseek(file_, long(kHeaderBytes + uint64_t(index) * record_bytes()), SEEK_SET) == 0 &&
      transfer_record(read, number, frame, layout_.velocities, crc) && read(&stored, 4);
  frame.frame = number;
  // A flipped bit would reach the outputs unseen (a NaN among them): the crc finds it.
  if (!ok || number != layout_.first_frame + index || stored != crc)
    throw InputError(path_.string() + ": record " + std::to_string(index) + " of the frame journal is damaged");
  return frame;
}

void FrameJournal::truncate(long long count) {
  const uint64_t bytes = kHeaderBytes + uint64_t(count) * record_bytes();
  if (std::fflush(file_) != 0 || ::ftruncate(fileno(file_), off_t(bytes)) != 0 ||
      std::fseek(file_, long(bytes), SEEK_SET) != 0)
    throw OutputError(io_failure(path_, "cannot truncate the frame journal"));
  records_ = count;
}

void FrameJournal::append(const FrameData& frame) {
  const size_t n = 3 * layout_.vertices, motions = 7 * layout_.motion_clusters;
  if (frame.positions.size() != n || (layout_.velocities && frame.velocities.size() != n) ||
      frame.leaf_attached.size() != layout_.leaves || frame.cluster_motions.size() != motions)
    throw std::logic_error("FrameJournal::append: frame " + std::to_string(frame.frame) +
                           " does not match the journal's layout");
  const int64_t number = frame.frame;
  uint32_t crc = 0;
  auto write = [&](const void* data, size_t bytes) { return std::fwrite(data, 1, bytes, file_) == bytes; };
  const bool ok = std::fseek(file_, 0, SEEK_END) == 0 && transfer_record(write, number, frame, layout_.velocities, crc) &&
                  write(&crc, 4);
  if (!ok) throw OutputError(io_failure(path_, "cannot append to the frame journal"));
  ++records_;
}

void FrameJournal::sync() {
  if (std::fflush(file_) != 0 || ::fdatasync(fileno(file_)) != 0)
    throw OutputError(io_failure(path_, "cannot flush the frame journal"));
}

}  // namespace treeanim
