#pragma once
// What every HDF5 writer and reader of treeanim shares: one lock for the library (the Debian
// build is not thread-safe, and sinks run on their own threads), the innermost error text,
// and an owning handle.
#include <hdf5.h>

#include <mutex>
#include <string>
#include <utility>

namespace treeanim {

// Takes the lock and turns HDF5's own error printing off (failures become exceptions).
std::unique_lock<std::mutex> hdf5_lock();

// The innermost message of HDF5's error stack; of a failed system call only its errno text
// ("... error message = 'File too large', buf = ..." => "File too large"). Clears the stack.
std::string hdf5_error_text();

// Owns one HDF5 identifier and closes it with the matching H5?close.
class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Handle(Handle&& other) noexcept : id_(other.id_), close_(other.close_) { other.id_ = -1; }
  Handle& operator=(Handle&& other) noexcept {
    std::swap(id_, other.id_);
    std::swap(close_, other.close_);
    return *this;
  }
  ~Handle() { reset(); }
  hid_t get() const { return id_; }
  // Closes now; returns false when HDF5 reports a failure (a flush that did not reach disk).
  bool reset() {
    const bool ok = id_ < 0 || close_(id_) >= 0;
    id_ = -1;
    return ok;
  }

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

// Creation properties of `property_class` (H5P_FILE_CREATE, H5P_GROUP_CREATE, H5P_DATASET_CREATE)
// without object times: HDF5 stamps every object with the clock by default, and then the same
// bake would not write the same bytes twice. Throws std::runtime_error when HDF5 refuses.
Handle untimed_creation(hid_t property_class);

}  // namespace treeanim
