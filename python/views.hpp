// numpy views of the engine's vectors (no copy), and a watch over the views of the State's vectors: a
// step may reallocate or resize them (water emitted or removed), after which an older view shows
// freed memory; the watch warns when a view still alive went stale (docs/python.md)
#pragma once
#include <soak/math.hpp>
#include <soak/state.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <functional>
#include <type_traits>
#include <utility>
#include <vector>

namespace soak::python {

namespace py = pybind11;

static_assert(sizeof(Vec3) == 3 * sizeof(float), "a Vec3 array is read as n x 3 floats");

// a numpy array over `data` (no copy) whose base is `owner`, the Python Simulation, so the memory's
// owner lives as long as the view
inline py::array viewOf(py::handle owner, const py::dtype& dtype, std::vector<py::ssize_t> shape,
                        std::vector<py::ssize_t> strides, const void* data, bool writable) {
  py::array a(dtype, std::move(shape), std::move(strides), data, owner);
  if (!writable) py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

// 1-D over a vector, n x 3 float32 over a vector of Vec3
template <class T>
py::array view(py::handle owner, const std::vector<T>& v, bool writable) {
  if constexpr (std::is_same_v<T, Vec3>)
    return viewOf(owner, py::dtype::of<float>(), {static_cast<py::ssize_t>(v.size()), 3}, {sizeof(Vec3), sizeof(float)},
                  v.data(), writable);
  else
    return viewOf(owner, py::dtype::of<T>(), {static_cast<py::ssize_t>(v.size())}, {sizeof(T)}, v.data(), writable);
}

class StateViews {
 public:
  // where a view's vector is now: its data and length
  using Where = std::function<std::pair<const void*, size_t>(State&)>;

  // remembers a view just made of the vector `where` finds (weakly: the view may die any time)
  void watch(const py::array& a, Where where, State& state) {
    const auto [data, size] = where(state);
    if (size == 0) return;                  // owns its empty buffer: nothing to go stale
    if (views_.size() > 64) prune(state);  // a loop that takes views without stepping
    views_.push_back({py::weakref(py::handle(a), py::handle()), std::move(where), data, size});
  }

  // after a step (GIL held): warns once about the views still alive whose vector moved or changed
  // length, and forgets them and the dead ones. Throws error_already_set if warnings are errors
  void warnAboutStale(State& state) {
    if (prune(state) == 0) return;
    if (PyErr_WarnEx(PyExc_RuntimeWarning,
                     "soak: a view of the state taken before this step is stale: the step added or removed "
                     "particles, so its memory may have been freed. Take views anew after each step, or copy "
                     "them (docs/python.md)",
                     1) != 0)
      throw py::error_already_set();
  }

 private:
  struct Watched {
    py::weakref ref;
    Where where;
    const void* data;
    size_t size;
  };

  // drops dead and stale views; returns how many live ones were stale
  size_t prune(State& state) {
    size_t stale = 0;
    std::vector<Watched> kept;
    for (Watched& w : views_) {
      if (w.ref().is_none()) continue;
      if (w.where(state) != std::make_pair(w.data, w.size)) {
        ++stale;
        continue;
      }
      kept.push_back(std::move(w));
    }
    views_ = std::move(kept);
    return stale;
  }

  std::vector<Watched> views_;
};

}  // namespace soak::python
