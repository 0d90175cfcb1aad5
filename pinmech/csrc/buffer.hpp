// A numpy array's memory seen through the buffer protocol (PEP 3118): C-contiguous float64
// or int32, no conversion and no copy. The per-pose entry points (frames_at, Core::rates)
// take their arrays so, and write their answers into arrays the caller allocated:
// nanobind's Eigen casters import and export an array through DLPack, a few microseconds
// a call, more than a pose's own work.
#pragma once

#include <Python.h>
#include <nanobind/nanobind.h>

#include <stdexcept>
#include <string>

namespace pinmech {

class Buffer {
 public:
  // `kind`: 'd' (float64) or 'i' (int32); `size`: the number of items wanted (-1: any).
  Buffer(nanobind::handle obj, char kind, Py_ssize_t size, bool writable, const char* name) {
    const int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj.ptr(), &view_, flags) != 0) {
      PyErr_Clear();
      throw std::invalid_argument(std::string(name) + ": a C-contiguous" + (writable ? " writable" : "") +
                                  " numpy array is needed");
    }
    const char* f = view_.format ? view_.format : "B";
    const char last = f[std::char_traits<char>::length(f) - 1];
    const Py_ssize_t itemsize = kind == 'd' ? 8 : 4;
    if (last != kind || view_.itemsize != itemsize || (f[0] == '>' || f[0] == '!')) {
      PyBuffer_Release(&view_);
      throw std::invalid_argument(std::string(name) + (kind == 'd' ? ": float64" : ": int32") + " array needed");
    }
    items_ = view_.len / itemsize;
    if (size >= 0 && items_ != size) {
      PyBuffer_Release(&view_);
      throw std::invalid_argument(std::string(name) + ": " + std::to_string(size) + " items needed, got " +
                                  std::to_string(items_));
    }
  }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer() { PyBuffer_Release(&view_); }

  Py_ssize_t size() const { return items_; }
  double* doubles() const { return static_cast<double*>(view_.buf); }
  const int* ints() const { return static_cast<const int*>(view_.buf); }

 private:
  Py_buffer view_{};
  Py_ssize_t items_ = 0;
};

}  // namespace pinmech
