// the Python module `soak` (docs/python.md): loads a scene from a file or a dict, steps it, shows the
// state's arrays as numpy views of the engine's own memory, moves pinned particles and colliders
// between steps and writes frames as `soak run` does
#include "simulation.hpp"

#include <soak/threads.hpp>

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

namespace py = pybind11;
using soak::python::Simulation;

namespace {

static_assert(sizeof(soak::Vec3) == 3 * sizeof(float), "a Vec3 array is read as n x 3 floats");

// a numpy array over `data` (no copy) whose base is `owner`, the Python Simulation, so the memory's
// owner lives as long as the view. Valid until the next step (docs/python.md: the vectors may grow)
py::array viewOf(py::handle owner, const py::dtype& dtype, std::vector<py::ssize_t> shape,
                 std::vector<py::ssize_t> strides, const void* data, bool writable) {
  py::array a(dtype, std::move(shape), std::move(strides), data, owner);
  if (!writable) py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

template <class T>
py::array view(py::handle owner, const std::vector<T>& v, bool writable) {
  return viewOf(owner, py::dtype::of<T>(), {static_cast<py::ssize_t>(v.size())}, {sizeof(T)}, v.data(), writable);
}

// n x 3 float32 over a vector of Vec3
py::array view3(py::handle owner, const std::vector<soak::Vec3>& v, bool writable) {
  return viewOf(owner, py::dtype::of<float>(), {static_cast<py::ssize_t>(v.size()), 3},
                {sizeof(soak::Vec3), sizeof(float)}, v.data(), writable);
}

Simulation& sim(py::handle self) { return self.cast<Simulation&>(); }

// a collider by index or name
int colliderOf(const Simulation& s, const py::object& collider) {
  if (py::isinstance<py::str>(collider)) return s.colliderIndex(collider.cast<std::string>());
  return collider.cast<int>();
}

py::object toPython(const nlohmann::ordered_json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

soak::Vec3 vec3Of(const py::array_t<float, py::array::c_style | py::array::forcecast>& a, const char* what) {
  if (a.size() != 3) throw soak::Error(std::string(what) + ": expected 3 numbers, got " + std::to_string(a.size()));
  return {a.data()[0], a.data()[1], a.data()[2]};
}

void bindLoading(py::module_& m) {
  m.def(
      "load",
      [](const std::string& path, const std::vector<std::string>& overrides) {
        return Simulation(soak::loadScene(path, overrides), soak::sceneAsRun(path, overrides));
      },
      py::arg("path"), py::arg("overrides") = std::vector<std::string>{},
      "Loads a scene file; overrides are \"json.path=value\" strings as soak run's --set.");
  m.def(
      "load_dict",
      [](const py::dict& scene, const py::object& baseDir, const std::vector<std::string>& overrides) {
        const std::string text = py::module_::import("json").attr("dumps")(scene, py::arg("indent") = 2).cast<std::string>();
        const std::string base = baseDir.is_none() ? py::module_::import("os").attr("getcwd")().cast<std::string>()
                                                   : py::str(baseDir).cast<std::string>();
        return Simulation(soak::loadSceneFromString(text, "<dict>", base, overrides), text + "\n");
      },
      py::arg("scene"), py::arg("base_dir") = py::none(), py::arg("overrides") = std::vector<std::string>{},
      "Loads a scene from a dict with a scene file's keys; relative mesh paths resolve against base_dir "
      "(default: the working directory).");
  m.def("set_threads", &soak::setThreadCount, py::arg("n"), "Sets the worker threads (results do not depend on it).");
  m.def("threads", &soak::threadCount, "The worker threads the parallel loops use.");
}

void bindArrays(py::class_<Simulation>& c) {
  const auto particles = [](py::handle self) -> soak::Particles& { return sim(self).state().particles; };
  c.def_property_readonly("positions", [=](py::handle self) { return view3(self, particles(self).x, true); });
  c.def_property_readonly("predicted_positions",
                          [=](py::handle self) { return view3(self, particles(self).xPred, true); });
  c.def_property_readonly("velocities", [=](py::handle self) { return view3(self, particles(self).v, true); });
  c.def_property_readonly("masses", [=](py::handle self) { return view(self, particles(self).mass, false); });
  c.def_property_readonly("inv_masses", [=](py::handle self) { return view(self, particles(self).invMass, false); });
  c.def_property_readonly("radii", [=](py::handle self) { return view(self, particles(self).radius, false); });
  c.def_property_readonly("phases", [=](py::handle self) { return view(self, particles(self).phase, false); });
  c.def_property_readonly("ids", [=](py::handle self) { return view(self, particles(self).id, false); });
  c.def_property_readonly("saturation",
                          [](py::handle self) { return view(self, sim(self).state().clothSaturation, false); });
  c.def_property_readonly("cloth_water", [](py::handle self) { return view(self, sim(self).state().clothWater, false); });
  c.def_property_readonly("cloth_buffer",
                          [](py::handle self) { return view(self, sim(self).state().clothBuffer, false); });
  c.def_property_readonly("pinned", [](py::handle self) { return view(self, sim(self).model().clothPinned, false); });
  c.def_property_readonly("triangles", [](py::handle self) {
    const auto& t = sim(self).model().triangles;
    return viewOf(self, py::dtype::of<int>(), {static_cast<py::ssize_t>(t.size()), 3}, {3 * sizeof(int), sizeof(int)},
                  t.data(), false);
  });
  c.def_property_readonly("ledger", [](py::handle self) {
    return viewOf(self, py::dtype::of<soak::WaterLedger>(), {}, {}, &sim(self).state().ledger, false);
  });
  c.def("water_mass", [](Simulation& s) {
    const soak::WaterMass w = soak::waterMass(s.state());
    return py::dict(py::arg("free") = w.free, py::arg("heldInCloth") = w.heldInCloth,
                    py::arg("inBuffers") = w.inBuffers, py::arg("emitted") = w.emitted,
                    py::arg("removedAtBounds") = w.removedAtBounds, py::arg("takenByCloth") = w.takenByCloth,
                    py::arg("total") = w.total);
  });
}

void bindScalars(py::class_<Simulation>& c) {
  c.def_property_readonly("name", [](const Simulation& s) { return s.scene().name; });
  c.def_property_readonly("description", [](const Simulation& s) { return s.scene().description; });
  c.def_property_readonly("time", [](Simulation& s) { return s.state().time; });
  c.def_property_readonly("step_count", [](Simulation& s) { return s.state().stepCount; });
  c.def_property_readonly("dt", [](const Simulation& s) { return s.model().solver.dt; });
  c.def_property_readonly("num_particles", [](Simulation& s) { return s.state().particles.size(); });
  c.def_property_readonly("num_cloth", [](const Simulation& s) { return s.model().numCloth; });
  c.def_property_readonly("frames", [](const Simulation& s) { return s.scene().output.frames; });
  c.def_property_readonly("steps_per_frame", [](const Simulation& s) { return s.scene().output.stepsPerFrame; });
  c.def_property_readonly("collider_names", [](const Simulation& s) {
    std::vector<std::string> names;
    for (const soak::Collider& k : s.model().colliders) names.push_back(k.name);
    return names;
  });
  c.def("state_hash", [](Simulation& s) { return soak::stateHash(s.state()); });
  c.def("check", [](Simulation& s) { return soak::checkState(s.model(), s.state()); });
}

void bindMotion(py::class_<Simulation>& c) {
  c.def("step", &Simulation::step, py::arg("steps") = 1, py::call_guard<py::gil_scoped_release>());
  c.def(
      "move_pinned",
      [](Simulation& s, const py::array_t<int64_t, py::array::c_style | py::array::forcecast>& indices,
         const py::array_t<float, py::array::c_style | py::array::forcecast>& positions) {
        if (positions.size() != 3 * indices.size())
          throw soak::Error("move_pinned: expected " + std::to_string(indices.size()) + " x 3 positions, got " +
                            std::to_string(positions.size()) + " numbers");
        const auto* xs = reinterpret_cast<const soak::Vec3*>(positions.data());
        s.movePinned({indices.data(), static_cast<size_t>(indices.size())}, {xs, static_cast<size_t>(indices.size())});
      },
      py::arg("indices"), py::arg("positions"));
  c.def(
      "collider_pose",
      [](const Simulation& s, const py::object& collider) {
        const soak::Keyframe k = s.colliderPose(colliderOf(s, collider));
        const soak::Quat& q = k.rotation;
        return py::make_tuple(py::array_t<float>(3, k.translation.data()),
                              py::array_t<float>(4, std::vector<float>{q.w(), q.x(), q.y(), q.z()}.data()));
      },
      py::arg("collider"));
  c.def(
      "set_collider_pose",
      [](Simulation& s, const py::object& collider, const py::array_t<float, py::array::c_style | py::array::forcecast>& t,
         const py::object& rotation) {
        const int k = colliderOf(s, collider);
        soak::Quat q = s.colliderPose(k).rotation;  // no rotation given: keep the current one
        if (!rotation.is_none()) {
          const auto r = rotation.cast<py::array_t<float, py::array::c_style | py::array::forcecast>>();
          if (r.size() != 4) throw soak::Error("set_collider_pose: rotation: expected a quaternion (w, x, y, z)");
          q = soak::Quat(r.data()[0], r.data()[1], r.data()[2], r.data()[3]);
        }
        s.setColliderPose(k, vec3Of(t, "set_collider_pose: translation"), q);
      },
      py::arg("collider"), py::arg("translation"), py::arg("rotation") = py::none());
}

void bindOutput(py::class_<Simulation>& c) {
  c.def(
      "write_frame",
      [](Simulation& s, const py::object& dir, int frame) { return toPython(s.writeFrame(py::str(dir), frame)); },
      py::arg("out_dir"), py::arg("frame"));
  c.def(
      "run",
      [](Simulation& s, const py::object& dir, const py::object& frames, const py::object& progress, bool overwrite) {
        const int n = frames.is_none() ? s.scene().output.frames : frames.cast<int>();
        // called between frames with the GIL held; Ctrl-C stops the run there
        const std::function<bool(int, int)> report = [&progress](int frame, int total) {
          py::gil_scoped_acquire gil;
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
          if (progress.is_none()) return true;
          const py::object r = progress(frame, total);
          return r.is_none() || r.cast<bool>();
        };
        const std::string out = py::str(dir);
        nlohmann::ordered_json last;
        {
          py::gil_scoped_release release;
          last = s.run(out, n, overwrite, report);
        }
        return toPython(last);
      },
      py::arg("out_dir"), py::arg("frames") = py::none(), py::arg("progress") = py::none(),
      py::arg("overwrite") = false);
}

}  // namespace

PYBIND11_MODULE(soak, m) {
  m.doc() = "soak: wet cloth simulation (Shao et al. 2017, Chen et al. 2012); docs/python.md";
  m.attr("__version__") = SOAK_VERSION;
  // soak::Error (a file, a JSON path, what was expected) as soak.Error; a diverged run as its subclass
  const auto& error = py::register_exception<soak::Error>(m, "Error");
  py::register_exception<soak::python::DivergedError>(m, "DivergedError", error.ptr());
  // the ledger as a numpy record: one field per member, named as in C++
  PYBIND11_NUMPY_DTYPE(soak::WaterLedger, emitted, removedAtBounds, particlesRemovedAtBounds, heldInCloth, inBuffers,
                       particlesAbsorbed, dripsEmitted, takenByCloth, particlesTakenByCloth);
  bindLoading(m);
  py::class_<Simulation> c(m, "Simulation", "A scene being simulated; made by soak.load or soak.load_dict.");
  bindArrays(c);
  bindScalars(c);
  bindMotion(c);
  bindOutput(c);
}
