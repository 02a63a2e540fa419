#include "formats/hdf5_support.h"

#include <stdexcept>

namespace treeanim {

namespace {

// The Debian HDF5 library is not built thread-safe: every HDF5 call holds this lock.
std::mutex hdf5_mutex;

}  // namespace

std::unique_lock<std::mutex> hdf5_lock() {
  std::unique_lock lock(hdf5_mutex);
  // HDF5 1.10.8's exit handler crashes (SIGSEGV in H5F__close_cb) closing a file whose
  // H5Fclose failed, e.g. after EFBIG or ENOSPC. Sinks never leave a file open otherwise, so
  // the handler has nothing to do; it must be declined before the library's first call.
  static const bool no_exit_handler = H5dont_atexit() >= 0;
  (void)no_exit_handler;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  return lock;
}

std::string hdf5_error_text() {
  std::string text;
  auto walk = [](unsigned, const H5E_error2_t* error, void* data) -> herr_t {
    auto* out = static_cast<std::string*>(data);
    if (out->empty() && error->desc) *out = error->desc;
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, walk, &text);
  H5Eclear2(H5E_DEFAULT);
  const std::string marker = "error message = '";
  const size_t start = text.find(marker);
  if (start != std::string::npos) {
    const size_t end = text.find('\'', start + marker.size());
    text = text.substr(start + marker.size(), end == std::string::npos ? std::string::npos : end - start - marker.size());
  }
  return text;
}

Handle untimed_creation(hid_t property_class) {
  Handle properties(H5Pcreate(property_class), H5Pclose);
  if (properties.get() < 0 || H5Pset_obj_track_times(properties.get(), false) < 0)
    throw std::runtime_error("HDF5 could not make creation properties (" + hdf5_error_text() + ")");
  return properties;
}

}  // namespace treeanim
