#include "files/output_file.h"

#include <algorithm>
#include <bit>

#include "common/errors.h"
#include "files/io_failure.h"

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

void OutputFile::write_u32_be(uint32_t value) {
  unsigned char bytes[4];
  for (int i = 0; i < 4; ++i) bytes[i] = static_cast<unsigned char>(value >> (8 * (3 - i)));
  write(bytes, 4);
}

void OutputFile::write_f32_be(const float* values, size_t count) {
  // Byte-swapped a block at a time: one write per value would cost a call per 4 bytes.
  constexpr size_t kBlock = 4096;
  uint32_t swapped[kBlock];
  for (size_t begin = 0; begin < count; begin += kBlock) {
    const size_t n = std::min(kBlock, count - begin);
    for (size_t i = 0; i < n; ++i) {
      const auto bits = std::bit_cast<uint32_t>(values[begin + i]);
      swapped[i] = std::endian::native == std::endian::big ? bits : __builtin_bswap32(bits);
    }
    write(swapped, n * sizeof(uint32_t));
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
