// the Python module `soak` (docs/python.md): loads a scene from a file or a dict, steps it, shows the
// state's arrays as numpy views of the engine's own memory, moves pinned particles and colliders
// between steps and writes frames as `soak run` does
#include "simulation.hpp"
#include "views.hpp"

#include <soak/threads.hpp>

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

namespace py = pybind11;
using soak::python::Simulation;
using soak::python::view;
using soak::python::viewOf;

namespace {

// the Python object: the simulation and the watch over its views
class PySimulation : public Simulation {
 public:
  explicit PySimulation(Simulation&& s) : Simulation(std::move(s)) {}
  soak::python::StateViews views;
};

PySimulation& sim(py::handle self) { return self.cast<PySimulation&>(); }

// a property showing one of the State's vectors, watched for staleness after each step
template <class T>
void defStateArray(py::class_<PySimulation>& c, const char* name, std::vector<T>& (*get)(soak::State&), bool writable) {
  c.def_property_readonly(name, [get, writable](py::handle self) {
    PySimulation& s = sim(self);
    py::array a = view(self, get(s.state()), writable);
    s.views.watch(a, [get](soak::State& st) {
      const std::vector<T>& v = get(st);
      return std::pair<const void*, size_t>(v.data(), v.size());
    }, s.state());
    return a;
  });
}

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
      [](const py::object& file, const std::vector<std::string>& overrides) {
        const std::string path = py::str(file);  // a str or a pathlib.Path
        return PySimulation(Simulation(soak::loadScene(path, overrides), soak::sceneAsRun(path, overrides)));
      },
      py::arg("path"), py::arg("overrides") = std::vector<std::string>{},
      "Loads a scene file; overrides are \"json.path=value\" strings as soak run's --set.");
  m.def(
      "load_dict",
      [](const py::dict& scene, const py::object& baseDir, const std::vector<std::string>& overrides) {
        const std::string text = py::module_::import("json").attr("dumps")(scene, py::arg("indent") = 2).cast<std::string>();
        const std::string base = baseDir.is_none() ? py::module_::import("os").attr("getcwd")().cast<std::string>()
                                                   : py::str(baseDir).cast<std::string>();
        return PySimulation(Simulation(soak::loadSceneFromString(text, "<dict>", base, overrides), text + "\n"));
      },
      py::arg("scene"), py::arg("base_dir") = py::none(), py::arg("overrides") = std::vector<std::string>{},
      "Loads a scene from a dict with a scene file's keys; relative mesh paths resolve against base_dir "
      "(default: the working directory).");
  m.def("set_threads", &soak::setThreadCount, py::arg("n"), "Sets the worker threads (results do not depend on it).");
  m.def("threads", &soak::threadCount, "The worker threads the parallel loops use.");
}

void bindArrays(py::class_<PySimulation>& c) {
  using soak::State;
  using soak::Vec3;
  defStateArray<Vec3>(c, "positions", [](State& s) -> std::vector<Vec3>& { return s.particles.x; }, true);
  defStateArray<Vec3>(c, "predicted_positions", [](State& s) -> std::vector<Vec3>& { return s.particles.xPred; }, true);
  defStateArray<Vec3>(c, "velocities", [](State& s) -> std::vector<Vec3>& { return s.particles.v; }, true);
  defStateArray<float>(c, "masses", [](State& s) -> std::vector<float>& { return s.particles.mass; }, false);
  defStateArray<float>(c, "inv_masses", [](State& s) -> std::vector<float>& { return s.particles.invMass; }, false);
  defStateArray<float>(c, "radii", [](State& s) -> std::vector<float>& { return s.particles.radius; }, false);
  defStateArray<int32_t>(c, "phases", [](State& s) -> std::vector<int32_t>& { return s.particles.phase; }, false);
  defStateArray<uint32_t>(c, "ids", [](State& s) -> std::vector<uint32_t>& { return s.particles.id; }, false);
  defStateArray<float>(c, "saturation", [](State& s) -> std::vector<float>& { return s.clothSaturation; }, false);
  defStateArray<double>(c, "cloth_water", [](State& s) -> std::vector<double>& { return s.clothWater; }, false);
  defStateArray<double>(c, "cloth_buffer", [](State& s) -> std::vector<double>& { return s.clothBuffer; }, false);
  c.def_property_readonly("pinned", [](py::handle self) { return view(self, sim(self).model().clothPinned, false); });
  c.def_property_readonly("triangles", [](py::handle self) {
    const auto& t = sim(self).model().triangles;
    return viewOf(self, py::dtype::of<int>(), {static_cast<py::ssize_t>(t.size()), 3}, {3 * sizeof(int), sizeof(int)},
                  t.data(), false);
  });
  c.def_property_readonly("ledger", [](py::handle self) {
    return viewOf(self, py::dtype::of<soak::WaterLedger>(), {}, {}, &sim(self).state().ledger, false);
  });
  c.def("water_mass", [](PySimulation& s) {
    const soak::WaterMass w = soak::waterMass(s.state());
    return py::dict(py::arg("free") = w.free, py::arg("heldInCloth") = w.heldInCloth,
                    py::arg("inBuffers") = w.inBuffers, py::arg("emitted") = w.emitted,
                    py::arg("removedAtBounds") = w.removedAtBounds, py::arg("takenByCloth") = w.takenByCloth,
                    py::arg("total") = w.total);
  }, "Where the water is now (kg): free, heldInCloth, inBuffers, emitted, removedAtBounds, takenByCloth, total.");
}

void bindScalars(py::class_<PySimulation>& c) {
  c.def_property_readonly("name", [](const PySimulation& s) { return s.scene().name; });
  c.def_property_readonly("description", [](const PySimulation& s) { return s.scene().description; });
  c.def_property_readonly("time", [](PySimulation& s) { return s.state().time; });
  c.def_property_readonly("step_count", [](PySimulation& s) { return s.state().stepCount; });
  c.def_property_readonly("dt", [](const PySimulation& s) { return s.model().solver.dt; });
  c.def_property_readonly("num_particles", [](PySimulation& s) { return s.state().particles.size(); });
  c.def_property_readonly("num_cloth", [](const PySimulation& s) { return s.model().numCloth; });
  c.def_property_readonly("frames", [](const PySimulation& s) { return s.scene().output.frames; });
  c.def_property_readonly("steps_per_frame", [](const PySimulation& s) { return s.scene().output.stepsPerFrame; });
  c.def_property_readonly("collider_names", [](const PySimulation& s) {
    std::vector<std::string> names;
    for (const soak::Collider& k : s.model().colliders) names.push_back(k.name);
    return names;
  });
  c.def("state_hash", [](PySimulation& s) { return soak::stateHash(s.state()); }, "The 64-bit hash of the whole state.");
  c.def("check", [](PySimulation& s) { return soak::checkState(s.model(), s.state()); },
        "'' while every particle is finite and below solver.maxSpeed, else what is wrong.");
}

void bindMotion(py::class_<PySimulation>& c) {
  c.def(
      "step",
      [](PySimulation& s, int steps) {
        {
          py::gil_scoped_release release;
          s.step(steps);
        }
        s.views.warnAboutStale(s.state());
      },
      py::arg("steps") = 1,
        "Advances `steps` steps of dt. Views taken before are valid only while no particle was added or removed.");
  c.def(
      "move_pinned",
      [](PySimulation& s, const py::array_t<int64_t, py::array::c_style | py::array::forcecast>& indices,
         const py::array_t<float, py::array::c_style | py::array::forcecast>& positions) {
        if (positions.size() != 3 * indices.size())
          throw soak::Error("move_pinned: expected " + std::to_string(indices.size()) + " x 3 positions, got " +
                            std::to_string(positions.size()) + " numbers");
        const auto* xs = reinterpret_cast<const soak::Vec3*>(positions.data());
        s.movePinned({indices.data(), static_cast<size_t>(indices.size())}, {xs, static_cast<size_t>(indices.size())});
      },
      py::arg("indices"), py::arg("positions"),
      "Puts pinned cloth particles at positions (k x 3, m); they stay there until moved again.");
  c.def(
      "collider_pose",
      [](const PySimulation& s, const py::object& collider) {
        const soak::Keyframe k = s.colliderPose(colliderOf(s, collider));
        const soak::Quat& q = k.rotation;
        return py::make_tuple(py::array_t<float>(3, k.translation.data()),
                              py::array_t<float>(4, std::vector<float>{q.w(), q.x(), q.y(), q.z()}.data()));
      },
      py::arg("collider"), "(translation, rotation (w, x, y, z)) of a collider (index or name) now.");
  c.def(
      "set_collider_pose",
      [](PySimulation& s, const py::object& collider, const py::array_t<float, py::array::c_style | py::array::forcecast>& t,
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
      py::arg("collider"), py::arg("translation"), py::arg("rotation") = py::none(),
      "Moves a collider (index or name) to this pose over the next step, then holds it there.");
}

void bindOutput(py::class_<PySimulation>& c) {
  c.def(
      "write_frame",
      [](PySimulation& s, const py::object& dir, int frame) { return toPython(s.writeFrame(py::str(dir), frame)); },
      py::arg("out_dir"), py::arg("frame"),
      "Writes the frame files of the state now as soak run does; returns the frame's stats line.");
  c.def(
      "run",
      [](PySimulation& s, const py::object& dir, const py::object& frames, const py::object& progress, bool overwrite) {
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
        s.views.warnAboutStale(s.state());
        return toPython(last);
      },
      py::arg("out_dir"), py::arg("frames") = py::none(), py::arg("progress") = py::none(),
      py::arg("overwrite") = false,
      "Writes frames 0 (now) to `frames` with stats.jsonl and scene.json as soak run does; progress(frame, "
      "frames) after each, False stops. Raises soak.DivergedError after writing a diverged frame.");
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
  py::class_<PySimulation> c(m, "Simulation", "A scene being simulated; made by soak.load or soak.load_dict.");
  bindArrays(c);
  bindScalars(c);
  bindMotion(c);
  bindOutput(c);
}
