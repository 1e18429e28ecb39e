// The `plslam` Python module: plslam::Slam (plslam/plslam.h), datasets and evaluation, with numpy
// arrays in and out. Trajectories are (N, 8) arrays in TUM order: t x y z qx qy qz qw.
#include <optional>
#include <string>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "plslam/eval/evaluate.h"
#include "plslam/io/dataset.h"
#include "plslam/io/trajectory_io.h"
#include "plslam/plslam.h"

namespace py = pybind11;
using namespace plslam;

namespace {

using ImageArray = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>;

// A header over the array's bytes (no copy): the caller holds the array for the whole call.
cv::Mat as_mat(const ImageArray& a, const char* side) {
  if (a.ndim() == 2) {
    return cv::Mat(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)), CV_8UC1,
                   const_cast<std::uint8_t*>(a.data()));
  }
  if (a.ndim() == 3 && a.shape(2) == 3) {
    return cv::Mat(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)), CV_8UC3,
                   const_cast<std::uint8_t*>(a.data()));
  }
  throw py::value_error(std::string("track: the ") + side +
                        " image must be a (height, width) uint8 array or (height, width, 3) BGR");
}

py::array_t<std::uint8_t> to_array(const cv::Mat& m) {
  const cv::Mat c = m.isContinuous() ? m : m.clone();
  py::array_t<std::uint8_t> out({c.rows, c.cols});
  std::memcpy(out.mutable_data(), c.data, static_cast<std::size_t>(c.rows) * c.cols);
  return out;
}

py::array_t<double> to_array(const Trajectory& traj) {
  py::array_t<double> out({static_cast<py::ssize_t>(traj.size()), py::ssize_t{8}});
  auto v = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < traj.size(); ++i) {
    const auto& p = traj[i];
    const Eigen::Quaterniond q(p.T.rotation());
    const double row[8] = {p.t, p.T.translation().x(), p.T.translation().y(), p.T.translation().z(),
                           q.x(), q.y(), q.z(), q.w()};
    for (py::ssize_t k = 0; k < 8; ++k) v(static_cast<py::ssize_t>(i), k) = row[k];
  }
  return out;
}

Trajectory to_trajectory(const py::array_t<double, py::array::c_style | py::array::forcecast>& a, const char* what) {
  if (a.ndim() != 2 || a.shape(1) != 8) {
    throw py::value_error(std::string(what) + ": expected an (N, 8) array: t x y z qx qy qz qw");
  }
  auto v = a.unchecked<2>();
  Trajectory out;
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    StampedPose p;
    p.t = v(i, 0);
    const Eigen::Quaterniond q(v(i, 7), v(i, 4), v(i, 5), v(i, 6));
    if (!(q.norm() > 0.5 && q.norm() < 2)) throw py::value_error(std::string(what) + ": a quaternion is not unit");
    p.T.linear() = q.normalized().toRotationMatrix();
    p.T.translation() = Eigen::Vector3d(v(i, 1), v(i, 2), v(i, 3));
    out.push_back(p);
  }
  return out;
}

py::object json_to_python(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

Preset parse_preset(const std::string& name) {
  if (name == "euroc") return Preset::kEuroc;
  if (name == "kitti") return Preset::kKitti;
  throw py::value_error("preset: 'euroc' or 'kitti', not '" + name + "'");
}

StereoCalibration calibration_of(const py::object& calib) {
  if (py::isinstance<StereoCalibration>(calib)) return calib.cast<StereoCalibration>();
  return read_calibration(calib.cast<std::filesystem::path>());
}

// A dataset folder (EuRoC or KITTI layout) as a sequence of (timestamp, left, right).
class PyDataset {
 public:
  PyDataset(const std::filesystem::path& path, std::size_t start, std::optional<std::size_t> max_frames) {
    io::DatasetOptions o;
    o.start = start;
    o.max_frames = max_frames;
    ds_ = io::open_dataset(path, o);
  }
  std::size_t size() const { return ds_->size(); }
  py::tuple get(std::ptrdiff_t i) const {
    if (i < 0) i += static_cast<std::ptrdiff_t>(size());
    if (i < 0 || static_cast<std::size_t>(i) >= size()) throw py::index_error("frame index out of range");
    io::StereoFrame f;
    {
      py::gil_scoped_release release;
      f = ds_->load(static_cast<std::size_t>(i));
    }
    return py::make_tuple(f.timestamp, to_array(f.left), to_array(f.right));
  }
  const io::Dataset& dataset() const { return *ds_; }

 private:
  std::unique_ptr<io::Dataset> ds_;
};

}  // namespace

PYBIND11_MODULE(plslam, m) {
  m.doc() = "plslam: stereo point-line visual SLAM (see docs/api.md)";
  m.def("version", &plslam::version);
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError);

  py::class_<StereoCalibration>(m, "StereoCalibration")
      .def(py::init([](int width, int height, double fx, double fy, double cx, double cy, double baseline) {
             return StereoCalibration{width, height, fx, fy, cx, cy, baseline};
           }),
           py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"),
           py::arg("baseline"))
      .def_readwrite("width", &StereoCalibration::width)
      .def_readwrite("height", &StereoCalibration::height)
      .def_readwrite("fx", &StereoCalibration::fx)
      .def_readwrite("fy", &StereoCalibration::fy)
      .def_readwrite("cx", &StereoCalibration::cx)
      .def_readwrite("cy", &StereoCalibration::cy)
      .def_readwrite("baseline", &StereoCalibration::baseline)
      .def("__repr__", [](const StereoCalibration& c) {
        return "StereoCalibration(" + std::to_string(c.width) + "x" + std::to_string(c.height) +
               ", fx=" + std::to_string(c.fx) + ", baseline=" + std::to_string(c.baseline) + ")";
      });
  m.def("read_calibration", &plslam::read_calibration, py::arg("path"));

  py::class_<TrackedFrame>(m, "TrackedFrame")
      .def_readonly("index", &TrackedFrame::index)
      .def_readonly("timestamp", &TrackedFrame::timestamp)
      .def_property_readonly("state", [](const TrackedFrame& f) { return std::string(to_string(f.state)); })
      .def_property_readonly("frame_state", [](const TrackedFrame& f) { return std::string(to_string(f.frame_state)); },
                             "tracked, relocalized, localized (trusted poses), recovering, unanchored or lost")
      .def_readonly("tracked", &TrackedFrame::tracked)
      .def_property_readonly("pose", [](const TrackedFrame& f) { return Eigen::Matrix4d(f.T_world_camera.matrix()); },
                             "4x4 T_world_camera of the left camera")
      .def_readonly("point_inliers", &TrackedFrame::point_inliers)
      .def_readonly("line_inliers", &TrackedFrame::line_inliers)
      .def_readonly("pose_covariance", &TrackedFrame::pose_covariance,
                    "6x6 covariance of the pose in the camera's frame, (translation, rotation); zeros without a pose")
      .def_readonly("keyframe", &TrackedFrame::keyframe)
      .def_readonly("relocalized", &TrackedFrame::relocalized)
      .def_readonly("new_map_segment", &TrackedFrame::new_map_segment)
      .def_readonly("tracking_ms", &TrackedFrame::tracking_ms);

  py::class_<Slam>(m, "System")
      .def(py::init([](const py::object& calibration, std::optional<std::filesystem::path> config,
                       const std::string& preset, bool lines, bool place_recognition, bool loop_closing,
                       bool sequential, bool deterministic, bool localization_only,
                       std::optional<std::filesystem::path> vocabulary) {
             SlamOptions o;
             o.preset = parse_preset(preset);
             if (config) o.config_file = *config;
             if (vocabulary) o.vocabulary = *vocabulary;
             o.lines = lines;
             o.place_recognition = place_recognition;
             o.loop_closing = loop_closing;
             o.sequential = sequential;
             o.deterministic = deterministic;
             o.localization_only = localization_only;
             const auto calib = calibration_of(calibration);
             py::gil_scoped_release release;  // loads the vocabulary
             return std::make_unique<Slam>(calib, o);
           }),
           py::arg("calibration"), py::kw_only(), py::arg("config") = py::none(), py::arg("preset") = "euroc",
           py::arg("lines") = true, py::arg("place_recognition") = true, py::arg("loop_closing") = true,
           py::arg("sequential") = false, py::arg("deterministic") = true, py::arg("localization_only") = false,
           py::arg("vocabulary") = py::none(),
           "calibration: a StereoCalibration or the path of a calibration file; deterministic=False: the "
           "free-running pipeline (runs differ); sequential=True: mapping in the tracking thread")
      .def(
          "track",
          [](Slam& s, const ImageArray& left, const ImageArray& right, double t) {
            const cv::Mat l = as_mat(left, "left");
            const cv::Mat r = as_mat(right, "right");
            py::gil_scoped_release release;  // other Python threads run while this frame is tracked
            return s.track(l, r, t);
          },
          py::arg("left"), py::arg("right"), py::arg("timestamp"))
      .def("trajectory", [](const Slam& s) { return to_array(s.trajectory()); },
           "(N, 8) array of the tracked frames: t x y z qx qy qz qw (T_world_camera)")
      .def("map",
           [](const Slam& s) {
             const auto snap = s.map();
             py::dict d;
             d["points"] = snap.points;
             d["lines"] = snap.lines;
             d["point_ids"] = snap.point_ids;
             d["line_ids"] = snap.line_ids;
             d["keyframes"] = to_array(snap.keyframes);
             return d;
           })
      .def("stats",
           [](const Slam& s) {
             const auto st = s.stats();
             py::dict d;
             d["frames"] = st.frames;
             d["tracked"] = st.tracked;
             d["lost_events"] = st.lost_events;
             d["relocalizations"] = st.relocalizations;
             d["loops"] = st.loops;
             d["keyframes"] = st.keyframes;
             d["points"] = st.points;
             d["lines"] = st.lines;
             d["gravity_aligned"] = st.gravity_aligned;
             return d;
           })
      .def_property_readonly("calibration", &Slam::calibration)
      .def(
          "use_imu",
          [](Slam& s, const PyDataset& d) {
            if (!d.dataset().imu()) throw py::value_error("use_imu: the dataset has no IMU (mav0/imu0)");
            s.use_imu(*d.dataset().imu());
          },
          py::arg("dataset"),
          "Before the first track(): the dataset's IMU, as plslam run uses it (visual-inertial "
          "initialisation, then a gravity-aligned world)")
      .def("load_map", &Slam::load_map, py::arg("path"), py::call_guard<py::gil_scoped_release>())
      .def("save_map", &Slam::save_map, py::arg("path"), py::call_guard<py::gil_scoped_release>())
      .def("shutdown", &Slam::shutdown, py::call_guard<py::gil_scoped_release>())
      .def_property_readonly("is_shut_down", &Slam::is_shut_down)
      .def("__enter__", [](Slam& s) -> Slam& { return s; }, py::return_value_policy::reference)
      .def("__exit__", [](Slam& s, const py::args&) {
        py::gil_scoped_release release;
        s.shutdown();
      });

  py::class_<PyDataset>(m, "Dataset", "An EuRoC or KITTI folder: dataset[i] is (timestamp, left, right)")
      .def(py::init<const std::filesystem::path&, std::size_t, std::optional<std::size_t>>(), py::arg("path"),
           py::arg("start") = 0, py::arg("max_frames") = py::none())
      .def("__len__", &PyDataset::size)
      .def("__getitem__", &PyDataset::get)
      .def_property_readonly("calibration", [](const PyDataset& d) { return d.dataset().calibration(); })
      .def_property_readonly("timestamps", [](const PyDataset& d) { return d.dataset().timestamps(); })
      .def_property_readonly("has_imu", [](const PyDataset& d) { return d.dataset().imu().has_value(); })
      .def_property_readonly("preset", [](const PyDataset& d) {
        return d.dataset().format() == io::DatasetFormat::kKitti ? "kitti" : "euroc";
      })
      .def_property_readonly("ground_truth", [](const PyDataset& d) -> py::object {
        if (!d.dataset().ground_truth()) return py::none();
        return to_array(*d.dataset().ground_truth());
      });

  auto ev = m.def_submodule("eval", "Trajectory evaluation (the library behind `plslam eval`)");
  ev.def(
      "ape",
      [](const py::array_t<double, py::array::c_style | py::array::forcecast>& gt,
         const py::array_t<double, py::array::c_style | py::array::forcecast>& est, const std::string& align,
         bool pair_by_index, double t_max_diff) {
        eval::EvalOptions o;
        o.align = eval::parse_align_mode(align);
        o.pair_by_index = pair_by_index;
        o.t_max_diff = t_max_diff;
        const auto g = to_trajectory(gt, "ground truth");
        const auto e = to_trajectory(est, "estimate");
        eval::EvalResult r;
        {
          py::gil_scoped_release release;
          r = eval::evaluate(g, e, o);
        }
        return json_to_python(eval::to_json(r));
      },
      py::arg("ground_truth"), py::arg("estimate"), py::arg("align") = "se3", py::arg("pair_by_index") = false,
      py::arg("t_max_diff") = 0.01,
      "Absolute and relative pose errors as `plslam eval --json` reports them: a dict with ape_trans_m "
      "{rmse, mean, median, ...}, rpe_trans_m, rpe_rot_deg, pairs, alignment");
  ev.def(
      "read_trajectory",
      [](const std::filesystem::path& path, const std::string& format) {
        io::TrajectoryFormat f = io::TrajectoryFormat::kTum;
        if (format == "kitti") {
          f = io::TrajectoryFormat::kKitti;
        } else if (format == "euroc") {
          f = io::TrajectoryFormat::kEuroc;
        } else if (format != "tum") {
          throw py::value_error("format: 'tum', 'kitti' or 'euroc'");
        }
        return to_array(io::read_trajectory(path, f));
      },
      py::arg("path"), py::arg("format") = "tum");
}
