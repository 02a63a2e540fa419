#include "io/output_file.h"

#include <bit>

#include "common/errors.h"
#include "io/staged_files.h"

namespace treeanim {

OutputFile::OutputFile(const std::filesystem::path& temporary, std::filesystem::path target)
    : target_(std::move(target)) {
  file_ = std::fopen(temporary.c_str(), "wb");
  if (!file_) throw OutputError(io_failure(target_, "cannot create " + temporary.string()));
}

OutputFile::~OutputFile() {
  if (file_) std::fclose(file_);
}

void OutputFile::write(const void* data, size_t bytes) {
  if (bytes > 0 && std::fwrite(data, 1, bytes, file_) != bytes) throw OutputError(io_failure(target_, "write failed"));
}

void OutputFile::write_u32_le(uint32_t value) {
  unsigned char bytes[4];
  for (int i = 0; i < 4; ++i) bytes[i] = static_cast<unsigned char>(value >> (8 * i));
  write(bytes, 4);
}

void OutputFile::write_f32_le(const float* values, size_t count) {
  if constexpr (std::endian::native == std::endian::little) {
    write(values, count * sizeof(float));
  } else {
    for (size_t i = 0; i < count; ++i) write_u32_le(std::bit_cast<uint32_t>(values[i]));
  }
}

void OutputFile::seek(uint64_t offset) {
  if (std::fflush(file_) != 0 || fseeko(file_, static_cast<off_t>(offset), SEEK_SET) != 0)
    throw OutputError(io_failure(target_, "seek failed"));
}

void OutputFile::close() {
  std::FILE* file = file_;
  file_ = nullptr;
  if (std::fflush(file) != 0 || std::ferror(file)) {
    std::fclose(file);
    throw OutputError(io_failure(target_, "write failed"));
  }
  if (std::fclose(file) != 0) throw OutputError(io_failure(target_, "close failed"));
}

}  // namespace treeanim
