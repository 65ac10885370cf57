// States gathered as numpy columns (bindings.h): MappedColumn's memory, StateColumns' layout.
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <new>
#include <utility>

#include "apps/python/bindings.h"

namespace gins::python {
namespace {

constexpr size_t kInitialBytes = 1 << 16;

size_t PageBytes(size_t values) {
  static const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
  const size_t bytes = std::max(values * sizeof(double), kInitialBytes);
  return (bytes + page - 1) / page * page;
}

// What a numpy array made from a MappedColumn holds on to: the mapping, unmapped with the array.
struct Mapping {
  void* data;
  size_t bytes;
};

}  // namespace

MappedColumn::~MappedColumn() { Release(); }

void MappedColumn::Release() {
  if (data_ != nullptr) munmap(data_, capacity_ * sizeof(double));
  data_ = nullptr;
  size_ = capacity_ = 0;
}

MappedColumn::MappedColumn(MappedColumn&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      capacity_(std::exchange(other.capacity_, 0)) {}

MappedColumn& MappedColumn::operator=(MappedColumn&& other) noexcept {
  if (this != &other) {
    Release();
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    capacity_ = std::exchange(other.capacity_, 0);
  }
  return *this;
}

void MappedColumn::Grow(size_t needed) {
  const size_t bytes = PageBytes(std::max(needed, 2 * capacity_));
  void* p = data_ == nullptr ? mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0)
                             : mremap(data_, capacity_ * sizeof(double), bytes, MREMAP_MAYMOVE);
  if (p == MAP_FAILED) throw std::bad_alloc();
  data_ = static_cast<double*>(p);
  capacity_ = bytes / sizeof(double);
}

py::array_t<double> MappedColumn::TakeNumpy(std::vector<py::ssize_t> shape) {
  if (size_ == 0) return py::array_t<double>(shape);
  auto* mapping = new Mapping{data_, capacity_ * sizeof(double)};
  py::capsule owner(mapping, [](void* m) {
    const Mapping* mp = static_cast<Mapping*>(m);
    munmap(mp->data, mp->bytes);
    delete mp;
  });
  py::array_t<double> a(shape, data_, owner);
  data_ = nullptr;
  size_ = capacity_ = 0;
  return a;
}

void StateColumns::Add(const api::State& s) {
  const double q_xyzw[4] = {s.q_wb[1], s.q_wb[2], s.q_wb[3], s.q_wb[0]};  // as in TUM
  t_.Append(&s.t, 1);
  p_.Append(s.p_enu, 3);
  q_.Append(q_xyzw, 4);
  v_.Append(s.v_enu, 3);
  if (with_lla_) lla_.Append(s.lla, 3);
  gyro_bias_.Append(s.gyro_bias, 3);
  acc_bias_.Append(s.acc_bias, 3);
  sigma_p_.Append(s.sigma_p, 3);
  sigma_v_.Append(s.sigma_v, 3);
  sigma_att_.Append(s.sigma_att, 3);
  odom_scale_.Append(&s.odom_scale, 1);
}

py::dict StateColumns::TakeNumpy() {
  const py::ssize_t n = static_cast<py::ssize_t>(t_.size());
  py::dict d;
  d["t"] = t_.TakeNumpy({n});
  d["p"] = p_.TakeNumpy({n, 3});
  d["q"] = q_.TakeNumpy({n, 4});
  d["v"] = v_.TakeNumpy({n, 3});
  if (with_lla_) d["lla"] = lla_.TakeNumpy({n, 3});
  d["gyro_bias"] = gyro_bias_.TakeNumpy({n, 3});
  d["acc_bias"] = acc_bias_.TakeNumpy({n, 3});
  d["sigma_p"] = sigma_p_.TakeNumpy({n, 3});
  d["sigma_v"] = sigma_v_.TakeNumpy({n, 3});
  d["sigma_att"] = sigma_att_.TakeNumpy({n, 3});
  d["odom_scale"] = odom_scale_.TakeNumpy({n});
  return d;
}

py::dict TakeNumpy(std::map<api::Stream, StateColumns>* streams) {
  py::dict d;
  for (auto& [stream, columns] : *streams) d[api::StreamName(stream)] = columns.TakeNumpy();
  streams->clear();
  return d;
}

}  // namespace gins::python
