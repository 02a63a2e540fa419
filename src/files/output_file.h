#pragma once
// A binary file being written to a temporary; every failure (open, short write, seek, a close
// that could not flush, e.g. no space left) throws OutputError naming the *target* path.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace treeanim {

class OutputFile {
 public:
  // Creates (truncates) `temporary`; messages name `target`.
  OutputFile(const std::filesystem::path& temporary, std::filesystem::path target);
  ~OutputFile();  // closes without reporting (the abort path)
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  void write(const void* data, size_t bytes);
  void write(std::string_view text) { write(text.data(), text.size()); }
  // Little- and big-endian integers and floats, whatever the host order.
  void write_u32_le(uint32_t value);
  void write_f32_le(const float* values, size_t count);
  void write_u32_be(uint32_t value);
  void write_f32_be(const float* values, size_t count);
  void seek(uint64_t offset);
  // Flushes and closes; throws when the data did not reach the file.
  void close();

 private:
  std::FILE* file_ = nullptr;
  std::filesystem::path target_;
};

}  // namespace treeanim
