// What the extension gins._gins shares between its translation units: states gathered into columns and
// handed to numpy without a copy, numpy arguments read as columns, and the module's parts.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "gins/gins.h"

namespace gins::python {

namespace py = pybind11;

// Called without the GIL every kSignalCheckRecords records of a long call (gins.run, a vectorised push):
// takes the GIL and raises, as a C++ exception, what a signal's Python handler raised (Ctrl-C's
// KeyboardInterrupt), so the call stops there. PyErr_CheckSignals does nothing off the main thread.
constexpr uint64_t kSignalCheckRecords = 4096;
inline void RaisePendingSignals() {
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
}

// A read-only numpy array over a std::vector it takes over (no copy): the array owns it through a capsule.
template <typename T>
py::array_t<T> ToNumpy(std::vector<T>&& values, std::vector<py::ssize_t> shape) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, owned->data(), owner);
}

// A column that grows without copying: anonymous memory grown by mremap (Linux), so appending n values
// costs n writes and one page fault per page, however long the log. The numpy array takes the mapping
// over (TakeNumpy).
class MappedColumn {
 public:
  MappedColumn() = default;
  ~MappedColumn();
  MappedColumn(MappedColumn&& other) noexcept;
  MappedColumn& operator=(MappedColumn&& other) noexcept;
  MappedColumn(const MappedColumn&) = delete;
  MappedColumn& operator=(const MappedColumn&) = delete;

  void Append(const double* values, size_t n) {
    if (size_ + n > capacity_) Grow(size_ + n);
    for (size_t i = 0; i < n; ++i) data_[size_ + i] = values[i];
    size_ += n;
  }
  size_t size() const { return size_; }
  // The values as a numpy array of `shape` (its product is size()); the column is left empty.
  py::array_t<double> TakeNumpy(std::vector<py::ssize_t> shape);

 private:
  void Grow(size_t needed);  // throws std::bad_alloc
  void Release();
  double* data_ = nullptr;
  size_t size_ = 0, capacity_ = 0;  // in values; capacity_ * sizeof(double) is a multiple of the page size
};

// One stream's states as columns, the names and layout of gins.Trajectory (docs/python.md): t (n), p, v,
// lla, gyro_bias, acc_bias, sigma_p, sigma_v, sigma_att (n×3), q (n×4, x y z w as in the TUM files),
// odom_scale (n).
class StateColumns {
 public:
  // Without lla, TakeNumpy has no "lla" (gins.run: the package converts p when it is asked for).
  explicit StateColumns(bool with_lla = true) : with_lla_(with_lla) {}
  void Add(const api::State& s);
  size_t size() const { return t_.size(); }
  // The columns as numpy arrays (a dict); the columns are left empty.
  py::dict TakeNumpy();

 private:
  bool with_lla_;
  MappedColumn t_, p_, q_, v_, lla_, gyro_bias_, acc_bias_, sigma_p_, sigma_v_, sigma_att_, odom_scale_;
};

// States by stream name ("eskf", "smoother", ...), as a dict of dicts of arrays.
py::dict TakeNumpy(std::map<api::Stream, StateColumns>* streams);

// A numpy argument (any number type, converted to double once, C order) read element by element.
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// The number of records an argument of push_*() holds: -1 for one (a scalar, or a vector of `width`
// numbers), else n (a 1-D array of n, or n×width). Throws ValueError naming `name` otherwise.
py::ssize_t Records(const DoubleArray& a, py::ssize_t width, const char* name);

// The module's parts (gins_module.cc, session_binding.cc).
void BindErrors(py::module_& m);
void BindSession(py::module_& m);

// A Python callback's exception is rethrown as it was (py::error_already_set); the API's errors and those
// of `gins run` become the gins.Error classes (BindErrors).
[[noreturn]] void ThrowUsage(const std::string& what);

}  // namespace gins::python
