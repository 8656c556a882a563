// The native half of `import envgi` (pybind11): scenes loaded once and rendered many times,
// environment maps and images as NumPy arrays. python/envgi/__init__.py wraps it with the
// progress bar and the keyword defaults a Python user sees.
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "accel/Bvh.h"
#include "accel/EmbreeAccel.h"
#include "core/PhysicalMemory.h"
#include "core/Transform.h"
#include "envmap/EnvironmentMap.h"
#include "gpu/CudaExecutor.h"
#include "image/Image.h"
#include "render/Cancellation.h"
#include "render/Renderer.h"
#include "scene/NameTables.h"
#include "scene/SceneLoader.h"
#include "study/ErrorMetrics.h"

namespace py = pybind11;

namespace envgi::python {

namespace {

// What the scene loader and the renderer throw for a bad file, value or setting, raised as
// ValueError with the same one line (FILE:LINE: what) the CLI prints.
struct BadInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

void requireFile(const std::string& path) {
  if (!std::filesystem::exists(path)) {
    PyErr_SetString(PyExc_FileNotFoundError, ("no such file: '" + path + "'").c_str());
    throw py::error_already_set();
  }
}

// Keyword arguments as the loader's -D values: True and False as Mitsuba writes them.
std::map<std::string, std::string> definesOf(const py::kwargs& params) {
  std::map<std::string, std::string> out;
  for (const auto& [key, value] : params) {
    const std::string name = py::str(key);
    if (py::isinstance<py::bool_>(value)) out[name] = value.cast<bool>() ? "true" : "false";
    else out[name] = py::str(value);
  }
  return out;
}

// A loaded scene and what renders of it keep: the CPU's Embree scene and the GPU's BVH, each
// built at the first render that needs it.
struct LoadedScene {
  std::unique_ptr<Scene> scene = std::make_unique<Scene>();
  std::unique_ptr<EmbreeAccel> accel;
  std::unique_ptr<Bvh> bvh;
  std::string name;
  Transform envToWorld;  // the map's placement as loaded, which set_environment turns and scales
  float envScale = 1.f;

  void loaded() {
    if (!scene->env) return;
    envToWorld = scene->env->options().toWorld;
    envScale = scene->env->options().scale;
  }
  // A new camera (perspective: its lookat), with the BVH kept: only the camera's rays change.
  void setCamera(const std::array<float, 3>& o, const std::array<float, 3>& t, const std::array<float, 3>& u) {
    if (scene->camera.orthographic)
      throw BadInput("set_camera: an orthographic sensor keeps the scene's own to_world (its scale is its view)");
    const Vec3f origin(o[0], o[1], o[2]), target(t[0], t[1], t[2]), up(u[0], u[1], u[2]);
    const Transform m = lookAt(origin, target, up);
    for (const auto& row : m.mat.m)
      for (float v : row)
        if (!std::isfinite(v)) throw BadInput("set_camera: origin, target and up must be finite and span a frame");
    scene->camera.toWorld = m;
    scene->finalize();
  }
  // The map turned about the vertical and scaled, from its placement as loaded (the viewer's
  // controls); its sampling tables, in its own frame, stay as they are.
  void setEnvironment(float rotation, float scale) {
    if (!scene->env) throw BadInput("set_environment: the scene has no environment map");
    if (!(scale >= 0.f) || !std::isfinite(scale) || !std::isfinite(rotation))
      throw BadInput("set_environment: the scale must be finite and not negative, the rotation finite");
    scene->env->setPlacement(envScale * scale, rotate(Vec3f(0.f, 1.f, 0.f), rotation) * envToWorld);
    scene->finalize();
  }
};

// The scene's integrator and sampler as a render's keywords set them, put back when the
// render ends however it ends (the next render of the scene starts from the scene's own).
class Overrides {
 public:
  Overrides(Scene& s, const std::optional<std::string>& integrator, const std::optional<std::string>& strategy,
            std::optional<uint32_t> seed)
      : s_(s), integrator_(s.integrator), sampler_(s.sampler) {
    try {
      if (integrator) s.integrator.type = findIntegrator(*integrator);
      if (strategy) s.integrator.setStrategy(*strategy);
      if (seed) s.sampler.seed = *seed;
      if (integrator || strategy || seed) s.finalize();
      changed_ = integrator || strategy || seed;
    } catch (...) {
      restore();
      throw;
    }
  }
  ~Overrides() {
    try {
      restore();
    } catch (const std::exception& e) {
      spdlog::error("restoring the scene's settings: {}", e.what());
    }
  }

 private:
  void restore() {
    s_.integrator = integrator_;
    s_.sampler = sampler_;
    if (changed_) s_.finalize();
  }
  Scene& s_;
  IntegratorSettings integrator_;
  SamplerSettings sampler_;
  bool changed_ = false;
};

// An image as a float32 array (H, W, 3) that owns its pixels.
py::array_t<float> toArray(Image&& img) {
  auto* pixels = new std::vector<float>(std::move(img.rgb));
  py::capsule owner(pixels, [](void* p) { delete static_cast<std::vector<float>*>(p); });
  return py::array_t<float>({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(3)}, pixels->data(), owner);
}

Image fromArray(const py::array_t<float, py::array::c_style | py::array::forcecast>& a) {
  if (a.ndim() != 3 || (a.shape(2) != 3 && a.shape(2) != 4))
    throw BadInput("an image is an array of shape (height, width, 3) or (height, width, 4)");
  Image img(int(a.shape(1)), int(a.shape(0)));
  const float* p = a.data();
  const size_t c = size_t(a.shape(2));
  for (size_t i = 0; i < size_t(img.width) * size_t(img.height); ++i)
    for (size_t k = 0; k < 3; ++k) img.rgb[3 * i + k] = p[c * i + k];
  return img;
}

// Runs work on a thread of its own while this one, holding the GIL a moment every 50 ms, lets
// Python see Ctrl-C (which sets cancel, then raises KeyboardInterrupt once the work has
// stopped) and calls onProgress with the share done.
Image runInterruptibly(const std::function<Image()>& work, std::atomic<bool>* cancel, std::atomic<float>* fraction,
                       const py::object& onProgress) {
  std::packaged_task<Image()> task(work);
  std::future<Image> result = task.get_future();
  bool interrupted = false;
  {
    py::gil_scoped_release release;
    std::thread worker(std::move(task));
    while (result.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
      py::gil_scoped_acquire acquire;
      if (!interrupted && PyErr_CheckSignals() != 0) {
        interrupted = true;
        cancel->store(true);
      }
      if (!interrupted && !onProgress.is_none()) onProgress(fraction->load());
    }
    worker.join();
  }
  if (interrupted) throw py::error_already_set();  // the KeyboardInterrupt PyErr_CheckSignals set
  try {
    Image img = result.get();
    if (!onProgress.is_none()) onProgress(1.f);
    return img;
  } catch (const RenderCancelled&) {
    throw py::error_already_set();
  }
}

template <class T>
py::array_t<T> arrayOf(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto* data = new std::vector<T>(std::move(v));
  py::capsule owner(data, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, data->data(), owner);
}

py::object render(LoadedScene& ls, std::optional<int> spp, std::optional<std::string> integrator,
                  std::optional<std::string> strategy, std::optional<uint32_t> seed, const std::string& device,
                  double timeLimit, int threads, const py::object& onProgress, std::optional<std::pair<int, int>> range,
                  float noiseThreshold, int minSpp, bool withStats) {
  if (spp && *spp <= 0) throw BadInput("spp must be positive, not " + std::to_string(*spp));
  if (timeLimit < 0.0) throw BadInput("time_limit must be positive (or 0: none)");
  if (!(noiseThreshold >= 0.f) || !std::isfinite(noiseThreshold))
    throw BadInput("noise_threshold must be finite and not negative (0: off)");
  if (minSpp < 2) throw BadInput("min_spp must be at least 2, not " + std::to_string(minSpp));
  Scene& scene = *ls.scene;
  Overrides set(scene, integrator, strategy, seed);
  requireLight(scene);
  const bool cuda = gpu::chooseCuda(device, "device", &scene);
  std::atomic<bool> cancel{false};
  std::atomic<float> fraction{0.f};
  RenderOptions ro;
  ro.spp = spp.value_or(-1);
  ro.threads = threads;
  ro.progress = false;
  ro.progressFraction = &fraction;
  ro.checkpointSeconds = 0.0;
  ro.cancel = &cancel;
  ro.timeLimitSeconds = timeLimit;
  ro.noiseThreshold = noiseThreshold;
  ro.adaptiveMinSpp = minSpp;
  FilmSums film;
  if (range) {  // the preparation refuses other integrators and a time limit (requireShareable)
    ro.firstSample = range->first, ro.sampleEnd = range->second;
    ro.filmOut = &film;
  }
  requireFilmFits(scene.camera, ro, physicalMemoryBytes());
  RenderStats st;
  std::string deviceName = "cpu";
  auto work = [&]() -> Image {
    if (!cuda) {
      if (!ls.accel) ls.accel = std::make_unique<EmbreeAccel>(scene);
      return envgi::render(scene, *ls.accel, ro, &st);
    }
    if (!ls.bvh) ls.bvh = std::make_unique<Bvh>(scene);
    // photon's camera passes run on the CPU, over Embree.
    if (scene.integrator.type == IntegratorType::Photon && !ls.accel) ls.accel = std::make_unique<EmbreeAccel>(scene);
    size_t bytes = 0;
    PreparedRender pr = gpu::prepareCudaRender(scene, *ls.bvh, ls.accel.get(), ro, 0, &bytes);
    deviceName = pr.executor->deviceName();
    return renderPasses(*pr.executor, scene.camera.width, scene.camera.height, pr.spp, ro, &st);
  };
  py::array_t<float> img = toArray(runInterruptibly(work, &cancel, &fraction, onProgress));
  // The render's own seconds (without loading or the GPU's upload), as the study times its runs.
  auto withStatsIfAsked = [&](py::object result) -> py::object {
    if (!withStats) return result;
    py::dict d;
    d["seconds"] = st.seconds;
    d["spp"] = st.sppDone;
    d["mean_spp"] = double(st.pixelSamples) / (double(scene.camera.width) * double(scene.camera.height));
    d["device"] = deviceName;
    return py::make_tuple(result, d);
  };
  if (!range) return withStatsIfAsked(std::move(img));
  const size_t n = film.sum.size();
  const py::ssize_t H = scene.camera.height, W = scene.camera.width;
  std::vector<float> sum(3 * n);
  for (size_t i = 0; i < n; ++i) sum[3 * i] = film.sum[i].x, sum[3 * i + 1] = film.sum[i].y, sum[3 * i + 2] = film.sum[i].z;
  py::dict out;
  out["sum"] = arrayOf(std::move(sum), {H, W, 3});
  out["weight"] = film.weightSum.empty() ? py::object(py::none()) : py::object(arrayOf(std::move(film.weightSum), {H, W}));
  out["samples"] = range->second - range->first;
  out["image"] = img;
  return withStatsIfAsked(std::move(out));
}

std::unique_ptr<LoadedScene> loadFile(const std::string& path, const py::kwargs& params) {
  requireFile(path);
  auto ls = std::make_unique<LoadedScene>();
  ls->name = path;
  loadScene(path, definesOf(params), *ls->scene);
  ls->loaded();
  return ls;
}

std::unique_ptr<LoadedScene> loadString(const std::string& xml, const py::kwargs& params) {
  auto ls = std::make_unique<LoadedScene>();
  ls->name = kSceneStringName;
  loadSceneString(xml, definesOf(params), *ls->scene);
  ls->loaded();
  return ls;
}

// Directions (n, 3) from an array, each a finite, non-zero vector.
std::vector<Vec3f> directionsOf(const py::array_t<float, py::array::c_style | py::array::forcecast>& a) {
  if (a.ndim() != 2 || a.shape(1) != 3) throw BadInput("directions are an array of shape (n, 3)");
  std::vector<Vec3f> out(size_t(a.shape(0)));
  for (size_t i = 0; i < out.size(); ++i) out[i] = Vec3f(a.data()[3 * i], a.data()[3 * i + 1], a.data()[3 * i + 2]);
  return out;
}

Vec3f normalOf(const std::array<float, 3>& n) {
  Vec3f v(n[0], n[1], n[2]);
  if (!(lengthSq(v) > 0.f) || !isFiniteVec(v)) throw BadInput("normal must be a finite, non-zero direction");
  return normalize(v);
}

EnvStrategy mapStrategy(const std::string& name) { return findStrategy(name, true).env; }


}  // namespace

}  // namespace envgi::python

PYBIND11_MODULE(_envgi, m) {
  using namespace envgi;
  using namespace envgi::python;
  m.doc() = "envgi's native module: see the envgi package for the documented API.";
  spdlog::set_pattern("envgi: [%l] %v");
  spdlog::set_level(spdlog::level::warn);

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const BadInput& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const std::runtime_error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });

  m.def("set_log_level", [](const std::string& level) {
    const spdlog::level::level_enum l = spdlog::level::from_str(level);
    if (level != "off" && l == spdlog::level::off) throw BadInput("unknown log level '" + level + "'");
    spdlog::set_level(l);
  });

  py::class_<LoadedScene>(m, "Scene")
      .def_property_readonly("width", [](const LoadedScene& s) { return s.scene->camera.width; })
      .def_property_readonly("height", [](const LoadedScene& s) { return s.scene->camera.height; })
      .def_property_readonly("spp", [](const LoadedScene& s) { return s.scene->sampler.sampleCount; })
      .def_property_readonly("integrator", [](const LoadedScene& s) { return integratorName(s.scene->integrator.type); })
      .def_property_readonly("strategy", [](const LoadedScene& s) { return s.scene->integrator.env.strategy; })
      .def_property_readonly("has_environment", [](const LoadedScene& s) { return bool(s.scene->env); })
      .def_property_readonly("accel_built", [](const LoadedScene& s) { return bool(s.accel) || bool(s.bvh); })
      .def("set_camera", &LoadedScene::setCamera, py::arg("origin"), py::arg("target"),
           py::arg("up") = std::array<float, 3>{0.f, 1.f, 0.f},
           "Points the camera from origin at target (Mitsuba's lookat); later renders reuse the BVH.")
      .def("set_environment", &LoadedScene::setEnvironment, py::arg("rotation") = 0.f, py::arg("scale") = 1.f,
           "Turns the map by rotation degrees about the vertical and scales it, from its placement as loaded.")
      .def("__repr__", [](const LoadedScene& s) {
        return "<envgi.Scene '" + s.name + "' " + std::to_string(s.scene->camera.width) + "x" +
               std::to_string(s.scene->camera.height) + ">";
      });

  m.def("load_file", &loadFile, py::arg("path"));
  m.def("load_string", &loadString, py::arg("xml"));
  m.def("render", &envgi::python::render, py::arg("scene"), py::arg("spp"), py::arg("integrator"), py::arg("strategy"),
        py::arg("seed"), py::arg("device"), py::arg("time_limit"), py::arg("threads"), py::arg("on_progress"),
        py::arg("sample_range"), py::arg("noise_threshold"), py::arg("min_spp"), py::arg("stats"));
  m.def(
      "image_error",
      [](const py::array_t<float, py::array::c_style | py::array::forcecast>& image,
         const py::array_t<float, py::array::c_style | py::array::forcecast>& reference) {
        const Image a = fromArray(image), r = fromArray(reference);
        if (a.width != r.width || a.height != r.height)
          throw BadInput(fmt::format("image_error: the image is {}x{}, the reference {}x{}", a.width, a.height,
                                     r.width, r.height));
        const ImageError e = imageError(a, r);
        py::dict d;
        d["rmse"] = e.rmse;
        d["relmse"] = e.relMse;
        d["worst_region_rmse"] = e.worstRegionRmse;
        return d;
      },
      py::arg("image"), py::arg("reference"));

  py::class_<EnvironmentMap>(m, "EnvironmentMap")
      .def(py::init([](const std::string& path, const std::string& layout) {
             requireFile(path);
             return std::make_unique<EnvironmentMap>(EnvironmentMap::loadLayout(path, layout));
           }),
           py::arg("path"), py::arg("layout") = "latlong")
      .def_property_readonly("width", [](const EnvironmentMap& e) { return e.view().width; })
      .def_property_readonly("height", [](const EnvironmentMap& e) { return e.view().height; })
      .def(
          "sample",
          [](const EnvironmentMap& e, int n, const std::string& strategy, uint32_t seed, std::array<float, 3> normal) {
            if (n <= 0 || n > (1 << 24)) throw BadInput("n must be from 1 to 16777216");
            const EnvStrategy s = mapStrategy(strategy);
            const EnvironmentMapView v = e.view();
            const Vec3f nw = v.fromLocal(normalOf(normal));
            Sampler smp;
            smp.type = SamplerType::Independent;
            smp.spp = uint32_t(n);
            smp.seed = seed;
            std::vector<float> dirs(3 * static_cast<size_t>(n)), pdfs(static_cast<size_t>(n));
            {
              py::gil_scoped_release release;
              for (int i = 0; i < n; ++i) {
                smp.start(0, uint32_t(i));
                const EnvSample es = v.sample(s, smp.get2D(), nw);
                dirs[3 * i] = es.dir.x, dirs[3 * i + 1] = es.dir.y, dirs[3 * i + 2] = es.dir.z;
                pdfs[i] = es.pdf;
              }
            }
            return py::make_tuple(arrayOf(std::move(dirs), {n, 3}), arrayOf(std::move(pdfs), {n}));
          },
          py::arg("n"), py::arg("strategy") = "importance", py::arg("seed") = 0,
          py::arg("normal") = std::array<float, 3>{0.f, 1.f, 0.f})
      .def(
          "pdf",
          [](const EnvironmentMap& e, const py::array_t<float, py::array::c_style | py::array::forcecast>& d,
             const std::string& strategy, std::array<float, 3> normal) {
            const std::vector<Vec3f> dirs = directionsOf(d);
            const EnvStrategy s = mapStrategy(strategy);
            const EnvironmentMapView v = e.view();
            const Vec3f nw = v.fromLocal(normalOf(normal));
            std::vector<float> out(dirs.size());
            for (size_t i = 0; i < dirs.size(); ++i)
              out[i] = lengthSq(dirs[i]) > 0.f ? v.pdf(s, normalize(dirs[i]), nw) : 0.f;
            return arrayOf(std::move(out), {py::ssize_t(dirs.size())});
          },
          py::arg("dirs"), py::arg("strategy") = "importance", py::arg("normal") = std::array<float, 3>{0.f, 1.f, 0.f})
      .def(
          "eval",
          [](const EnvironmentMap& e, const py::array_t<float, py::array::c_style | py::array::forcecast>& d) {
            const std::vector<Vec3f> dirs = directionsOf(d);
            const EnvironmentMapView v = e.view();
            std::vector<float> out(3 * dirs.size());
            for (size_t i = 0; i < dirs.size(); ++i) {
              const Color c = lengthSq(dirs[i]) > 0.f ? v.eval(normalize(dirs[i])) : Color(0.f);
              out[3 * i] = c.x, out[3 * i + 1] = c.y, out[3 * i + 2] = c.z;
            }
            return arrayOf(std::move(out), {py::ssize_t(dirs.size()), 3});
          },
          py::arg("dirs"));

  m.def(
      "read_image",
      [](const std::string& path) {
        requireFile(path);
        return toArray(loadImage(path));
      },
      py::arg("path"));
  m.def(
      "write_image",
      [](const std::string& path, const py::array_t<float, py::array::c_style | py::array::forcecast>& a,
         float exposure) {
        SaveOptions so;
        so.exposure = exposure;
        saveImage(fromArray(a), path, so);
      },
      py::arg("path"), py::arg("image"), py::arg("exposure") = 0.f);
}
