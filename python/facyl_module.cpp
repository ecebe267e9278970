/*
 * facyl: Python bindings (pybind11). numpy in, numpy out; the GIL is released while facyl
 * computes. Every input is checked here, before C++ sees it: ValueError / TypeError with the
 * argument's name, never a crash.
 */
#include <facyl/tools/cylinder_fit.h>
#include <facyl/tools/detect_json.h>
#include <facyl/tools/fit_options.h>
#include <facyl/tools/recognizer_options.h>
#include <facyl/tools/settings_table.h>
#include <facyl/tools/track_json.h>
#include <facyl/tools/tracker_options.h>

#include <facyl/features/normal_curvature_estimation.h>
#include <facyl/recognition/cylinder_classifier.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/sample_consensus_alt/cylinder_fitting.h>
#include <facyl/sample_consensus_alt/hough_cylinder_estimation.h>
#include <facyl/simulation/cylinder_simulation.h>
#include <facyl/simulation/tabletop_scene.h>
#include <facyl/simulation/tabletop_sequence.h>
#include <facyl/tracking/cylinder_tracker.h>

#include <pcl/ModelCoefficients.h>
#include <pcl/console/print.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace py = pybind11;

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Cues = pcl::PointCloud<facyl::NormalCurvature>;

// ------------------------------------------------------------------------------ inputs

/** The float32 or float64 array \a obj as float64 values, checked to have \a cols columns
 * (ndim 2) or, with \a frame, shape (H, W, cols); float16 raises TypeError. */
py::array_t<double, py::array::c_style | py::array::forcecast>
floatArray(const py::handle& obj, const char* name, py::ssize_t cols, bool frame = false)
{
  // numpy arrays, and anything with the buffer protocol (Open3D's Vector3dVector, memoryview).
  if (!py::isinstance<py::array>(obj) && !py::isinstance<py::buffer>(obj))
    throw py::type_error(std::string(name) +
                         ": expected a numpy array (or an Open3D "
                         "Vector3dVector), got " +
                         std::string(py::str(py::type::of(obj).attr("__name__"))));
  const auto a = py::isinstance<py::array>(obj)
                   ? py::reinterpret_borrow<py::array>(obj)
                   : py::array(py::reinterpret_borrow<py::buffer>(obj));
  // float16 is refused, not converted: its 3 significant digits cannot hold a point of a
  // scene (a millimetre at 2 m needs 4).
  if (a.dtype().kind() != 'f' || a.itemsize() < 4)
    throw py::type_error(std::string(name) + ": expected float32 or float64 values, got dtype " +
                         std::string(py::str(a.dtype())) +
                         (a.itemsize() == 2 ? " (convert it: .astype(numpy.float32))" : ""));
  const bool ok =
    frame ? (a.ndim() == 3 && a.shape(2) == cols) : (a.ndim() == 2 && a.shape(1) == cols);
  if (!ok) {
    std::string shape = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i)
      shape += (i ? ", " : "") + std::to_string(a.shape(i));
    throw py::value_error(std::string(name) + ": expected shape " + (frame ? "(H, W, " : "(N, ") +
                          std::to_string(cols) + "), got " + shape + (a.ndim() == 1 ? ",)" : ")"));
  }
  if (a.size() == 0)
    throw py::value_error(std::string(name) + ": the array is empty");
  return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
}

/** Rows of \a a (N x 3, float64) times \a scale as PCL points; NaN rows stay (as missing
 * points). Raises when no row is finite. */
Cloud::Ptr
toCloud(const py::array_t<double, py::array::c_style | py::array::forcecast>& a, const char* name,
        double scale = 1.0)
{
  const auto n = static_cast<std::size_t>(a.size() / 3);
  Cloud::Ptr cloud(new Cloud);
  cloud->resize(n);
  const double* d = a.data();
  std::size_t finite = 0;
  for (std::size_t i = 0; i < n; ++i) {
    auto& p = (*cloud)[i];
    p.x = static_cast<float>(scale * d[3 * i]);
    p.y = static_cast<float>(scale * d[3 * i + 1]);
    p.z = static_cast<float>(scale * d[3 * i + 2]);
    finite += std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
  }
  cloud->is_dense = finite == n;
  if (finite == 0)
    throw py::value_error(std::string(name) + ": no row is finite (all NaN or inf)");
  return cloud;
}

py::array_t<float>
vector3(const Eigen::Vector3f& v)
{
  py::array_t<float> a(3);
  std::memcpy(a.mutable_data(), v.data(), 3 * sizeof(float));
  return a;
}

// ------------------------------------------------------------------- one vocabulary

using facyl_cli::OptionValue;
using facyl_cli::ValueKind;

/** A keyword's value as the user wrote it, for messages: its repr (0.1, not the double's
 * 0.10000000000000001). */
std::string
written(const py::handle& v)
{
  return std::string(py::repr(v));
}

/** \a v as a number; nullopt when it is not one (a bool is not). */
std::optional<double>
numberOf(const py::handle& v)
{
  if (py::isinstance<py::bool_>(v) || py::isinstance<py::str>(v) || !PyNumber_Check(v.ptr()))
    return std::nullopt;
  const double d = PyFloat_AsDouble(v.ptr());
  if (d == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    return std::nullopt;
  }
  return d;
}

/** Keyword \a keyword's value \a v for option \a o, as that option's kind of value. A str is
 * read as the tools read the option's text ("0.01,0.25", "auto").
 * \throws py::type_error or py::value_error naming the keyword. */
template <typename S>
OptionValue
keywordValue(const facyl_cli::Option<S>& o, const std::string& keyword, const py::handle& v)
{
  const auto wrong = [&](const std::string& expected) {
    return py::type_error(keyword + ": expected " + expected + ", got " + written(v));
  };
  OptionValue out;
  if (py::isinstance<py::str>(v) && o.kind != ValueKind::Switch) {
    try {
      return facyl_cli::readOptionValue(o, v.cast<std::string>());
    }
    catch (const std::invalid_argument& e) {
      throw py::value_error(keyword + ": " + e.what());
    }
  }
  out.written = written(v);
  const auto numbers = [&](std::size_t n) {
    std::vector<double> values;
    if (!py::isinstance<py::sequence>(v) || py::len(v) != n)
      return values;
    for (const auto& x : py::reinterpret_borrow<py::sequence>(v)) {
      const auto d = numberOf(x);
      if (!d || !std::isfinite(*d))
        return std::vector<double>();
      values.push_back(*d);
    }
    return values;
  };
  switch (o.kind) {
  case ValueKind::Switch:
    if (!py::isinstance<py::bool_>(v) &&
        !py::isinstance(v, py::module_::import("numpy").attr("bool_")))
      throw wrong("True or False");
    break;
  case ValueKind::Integer: {
    if (py::isinstance<py::bool_>(v))
      throw wrong("an integer");
    if (PyIndex_Check(v.ptr())) { // int, numpy's integers: beyond 64 bits, saturated
      int overflow = 0;
      const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(v.ptr()));
      out.integer = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
      out.overflow = overflow != 0;
      if (overflow)
        out.integer = overflow > 0 ? std::numeric_limits<long long>::max()
                                   : std::numeric_limits<long long>::min();
      break;
    }
    const auto d = numberOf(v); // a float with an integral value is taken
    if (!d)
      throw wrong("an integer");
    if (!(std::isfinite(*d) && std::floor(*d) == *d && std::abs(*d) < 9e18))
      throw py::value_error(keyword + ": " + out.written + " is not an integer");
    out.integer = static_cast<long long>(*d);
    break;
  }
  case ValueKind::Number: {
    const auto d = numberOf(v);
    if (!d)
      throw wrong("a number");
    if (!std::isfinite(*d))
      throw py::value_error(keyword + ": " + out.written + " is not a number");
    out.number = *d;
    break;
  }
  case ValueKind::Pair: {
    const auto values = numbers(2);
    if (values.empty())
      throw py::value_error(keyword + ": expected two numbers (A, B), got " + out.written);
    out.pair = {values[0], values[1]};
    break;
  }
  case ValueKind::Vector3: {
    const auto values = numbers(3);
    if (values.empty())
      throw py::value_error(keyword + ": expected three numbers (x, y, z), got " + out.written);
    out.vector = Eigen::Vector3d(values[0], values[1], values[2]).cast<float>();
    break;
  }
  case ValueKind::Word:
    throw wrong("a str");
  }
  return out;
}

/** Keyword arguments (name, value) applied to \a s by \a table's rows: the tools' option
 * names with '_' for '-', their checks and their messages. None is "not given", as False is
 * for a switch. \throws py::value_error / py::type_error naming the keyword. */
template <typename S>
void
applyKeywords(const facyl_cli::SettingsTable<S>& table,
              const std::vector<std::pair<std::string, py::object>>& keywords, S& s)
{
  std::vector<facyl_cli::GivenOption<S>> given;
  for (const auto& [keyword, value] : keywords) {
    if (value.is_none())
      continue;
    std::string name = keyword;
    std::replace(name.begin(), name.end(), '_', '-');
    const facyl_cli::Option<S>* o = table.find(name);
    if (!o || o->tool_only)
      throw py::value_error("unknown option " + keyword);
    const OptionValue v = keywordValue(*o, keyword, value);
    if (o->kind == ValueKind::Switch && !py::cast<bool>(value))
      continue;
    for (const auto& g : given)
      if (g.option == o)
        throw py::value_error("give " + facyl_cli::Vocabulary{true}.option(o->name) + " once (" +
                              facyl_cli::Vocabulary{true}.option(o->alias) +
                              " is its old spelling)");
    given.push_back({o, keyword, v});
  }
  try {
    facyl_cli::applyOptions(table, given, facyl_cli::Vocabulary{true}, s);
  }
  catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

/** The keyword arguments of \a options, in their order. */
std::vector<std::pair<std::string, py::object>>
keywordList(const py::dict& options)
{
  std::vector<std::pair<std::string, py::object>> list;
  for (const auto& [key, value] : options)
    list.emplace_back(key.cast<std::string>(), py::reinterpret_borrow<py::object>(value));
  return list;
}

// ---------------------------------------------------------------------------- results

/** \a j, a result as the tools write it (json_writer.h: numbers already carry their digits),
 * as Python objects: dicts keep the fields' order, null is None. */
py::object
toPython(const facyl_cli::Json& j)
{
  using T = facyl_cli::Json::value_t;
  switch (j.type()) {
  case T::null:
    return py::none();
  case T::boolean:
    return py::bool_(j.get<bool>());
  case T::number_integer:
    return py::int_(j.get<std::int64_t>());
  case T::number_unsigned:
    return py::int_(j.get<std::uint64_t>());
  case T::number_float:
    return py::float_(j.get<double>());
  case T::string: {
    const auto& text = j.get_ref<const std::string&>();
    return py::reinterpret_steal<py::object>(
      PyUnicode_DecodeUTF8(text.data(), static_cast<Py_ssize_t>(text.size()), "replace"));
  }
  case T::array: {
    py::list list;
    for (const auto& x : j)
      list.append(toPython(x));
    return std::move(list);
  }
  case T::object: {
    py::dict dict;
    for (const auto& [key, value] : j.items())
      dict[py::str(key)] = toPython(value);
    return std::move(dict);
  }
  default:
    return py::none();
  }
}

/** The digits of the numbers of Python's results: a float32 exactly. */
constexpr int kPythonDigits = 9;

/** A fitted cylinder as Python sees it. */
struct PyCylinder {
  facyl::CylinderModel model;
};

// ------------------------------------------------------------------- normals, curvatures

using FitSettings = facyl_cli::FitSettings;

/** facyl_fit's settings from keywords (fitOptions). \throws py::value_error. */
FitSettings
fitSettings(const std::vector<std::pair<std::string, py::object>>& keywords)
{
  FitSettings s;
  applyKeywords(facyl_cli::fitOptions(), keywords, s);
  return s;
}

/** \a neighbours, or its old spelling \a k, as the fit reads them. */
int
neighboursOf(const py::object& neighbours, const py::object& k)
{
  const bool both = !k.is_none() && neighbours.cast<int>() != FitSettings{}.neighbours;
  std::vector<std::pair<std::string, py::object>> keywords{{"k", k}};
  if (k.is_none() || both)
    keywords.insert(keywords.begin(), {"neighbours", neighbours});
  return fitSettings(keywords).neighbours;
}

void
checkRows(std::size_t points, int k)
{
  if (points < static_cast<std::size_t>(k))
    throw py::value_error("points: " + std::to_string(points) +
                          " rows are fewer than k = " + std::to_string(k) + " neighbours");
}

py::tuple
estimateNormalsCurvatures(const py::object& points, const py::object& neighbours,
                          const py::object& k_alias)
{
  const int k = neighboursOf(neighbours, k_alias);
  const auto a = floatArray(points, "points", 3);
  const Cloud::Ptr cloud = toCloud(a, "points");
  checkRows(cloud->size(), k);
  Cues::Ptr cues;
  {
    py::gil_scoped_release release;
    cues = facyl_cli::estimateFitCues(cloud, k, 0, nullptr);
  }
  const auto n = static_cast<py::ssize_t>(cloud->size());
  py::array_t<float> normals({n, py::ssize_t(3)}), directions({n, py::ssize_t(3)}), k_max(n),
    k_min(n);
  auto nm = normals.mutable_unchecked<2>();
  auto dm = directions.mutable_unchecked<2>();
  auto kx = k_max.mutable_unchecked<1>();
  auto kn = k_min.mutable_unchecked<1>();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& c = (*cues)[static_cast<std::size_t>(i)];
    const bool ok = cues->size() == cloud->size();
    nm(i, 0) = ok ? c.normal_x : nan;
    nm(i, 1) = ok ? c.normal_y : nan;
    nm(i, 2) = ok ? c.normal_z : nan;
    dm(i, 0) = ok ? c.principal_curvature_x : nan;
    dm(i, 1) = ok ? c.principal_curvature_y : nan;
    dm(i, 2) = ok ? c.principal_curvature_z : nan;
    kx(i) = ok ? c.pc1 : nan;
    kn(i) = ok ? c.pc2 : nan;
  }
  return py::make_tuple(normals, directions, k_max, k_min);
}

// ------------------------------------------------------------------------------- fitting

/** The fit of facyl_fit (apps/common/include/facyl/tools/cylinder_fit.h) on \a cloud (already in
 * metres): cues estimated unless \a normals, then the method of \a s. */
std::vector<facyl::CylinderModel>
fitCloud(const Cloud::ConstPtr& cloud, const pcl::PointCloud<pcl::Normal>::ConstPtr& normals,
         const FitSettings& s, std::string* why = nullptr)
{
  const Cues::Ptr cues = facyl_cli::estimateFitCues(cloud, s.neighbours, 0, normals);
  if (cues->size() != cloud->size())
    return {};
  if (s.method == "pcl-ransac")
    return facyl_cli::pclRansacFit(cloud, *cues, s.params);
  return facyl_cli::houghFit(cloud, cues, s, why);
}

pcl::PointCloud<pcl::Normal>::Ptr
toNormals(const py::object& normals, std::size_t rows)
{
  if (normals.is_none())
    return nullptr;
  const auto a = floatArray(normals, "normals", 3);
  if (static_cast<std::size_t>(a.shape(0)) != rows)
    throw py::value_error("normals: " + std::to_string(a.shape(0)) + " rows, points has " +
                          std::to_string(rows));
  pcl::PointCloud<pcl::Normal>::Ptr out(new pcl::PointCloud<pcl::Normal>);
  out->resize(rows);
  const double* d = a.data();
  for (std::size_t i = 0; i < rows; ++i) {
    auto& n = (*out)[i];
    n.normal_x = static_cast<float>(d[3 * i]);
    n.normal_y = static_cast<float>(d[3 * i + 1]);
    n.normal_z = static_cast<float>(d[3 * i + 2]);
  }
  return out;
}

std::vector<PyCylinder>
fitCylinders(const py::object& points, const py::object& normals,
             const std::vector<std::pair<std::string, py::object>>& keywords)
{
  const auto a = floatArray(points, "points", 3);
  const FitSettings s = fitSettings(keywords);
  // Millimetres are converted in double precision, before the points become floats.
  const float to_metres = facyl_cli::metresPerUnit(s.units);
  const Cloud::Ptr cloud = toCloud(a, "points", facyl_cli::metresPerUnitExact(s.units));
  const auto given = toNormals(normals, cloud->size());
  checkRows(cloud->size(), s.neighbours);
  const facyl_cli::Vocabulary say{true};
  const std::string units =
    facyl_cli::unitsProblem(*cloud, s.units, say.option("units", "mm"), say.option("units", "m"));
  if (!units.empty())
    throw py::value_error("points: " + units);
  std::vector<facyl::CylinderModel> models;
  std::string why;
  {
    py::gil_scoped_release release;
    models = fitCloud(cloud, given, s, &why);
  }
  // No cylinder is an answer, not an error; its reason (the radius limits excluding the one
  // there, too few points, ...) is a UserWarning.
  if (models.empty() && !why.empty() &&
      PyErr_WarnEx(PyExc_UserWarning, ("fit_cylinders: no cylinder: " + why).c_str(), 1) != 0)
    throw py::error_already_set();
  std::vector<PyCylinder> out;
  for (auto& m : models) {
    facyl_cli::scaleModel(m, 1.f / to_metres);
    out.push_back({std::move(m)});
  }
  return out;
}

/** Median milliseconds of \a repeats calls of the same fit inside C++ (no Python between
 * them): the reference for the binding's overhead (fit_cylinders' defaults, as
 * python/bench_binding.py calls it). */
double
timeFitInCpp(const py::object& points, int repeats, const py::object& k)
{
  const FitSettings s = fitSettings({{"neighbours", k}});
  const auto a = floatArray(points, "points", 3);
  const Cloud::Ptr cloud = toCloud(a, "points");
  checkRows(cloud->size(), s.neighbours);
  if (repeats < 1 || repeats > 100000)
    throw py::value_error("repeats: must be in [1, 100000]");
  std::vector<double> ms;
  py::gil_scoped_release release;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto models = fitCloud(cloud, nullptr, s);
    ms.push_back(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

// -------------------------------------------------------------------------------- detect

using RgbCloud = pcl::PointCloud<pcl::PointXYZRGBA>;
using Recognizer = facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA>;

RgbCloud::Ptr
frameCloud(const py::object& points, const py::object& colors, bool& organized)
{
  const auto a = py::reinterpret_borrow<py::array>(points.ptr());
  organized = py::isinstance<py::array>(points) && a.ndim() == 3;
  const auto xyz = floatArray(points, "points", 3, organized);
  const py::ssize_t h = organized ? xyz.shape(0) : 1, w = organized ? xyz.shape(1) : xyz.shape(0);
  py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast> rgb;
  if (!colors.is_none()) {
    if (!py::isinstance<py::array>(colors))
      throw py::type_error("colors: expected a numpy array of uint8");
    const auto c = py::reinterpret_borrow<py::array>(colors);
    if (c.dtype().kind() != 'u' || c.itemsize() != 1)
      throw py::type_error("colors: expected dtype uint8, got " + std::string(py::str(c.dtype())));
    const bool same = organized
                        ? (c.ndim() == 3 && c.shape(0) == h && c.shape(1) == w && c.shape(2) == 3)
                        : (c.ndim() == 2 && c.shape(0) == w && c.shape(1) == 3);
    if (!same)
      throw py::value_error("colors: expected the shape of points (RGB, uint8)");
    rgb = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(c);
  }
  RgbCloud::Ptr cloud(new RgbCloud);
  cloud->resize(static_cast<std::size_t>(h * w));
  cloud->width = static_cast<std::uint32_t>(w);
  cloud->height = static_cast<std::uint32_t>(h);
  cloud->is_dense = false;
  const double* d = xyz.data();
  std::size_t finite = 0;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    auto& p = (*cloud)[i];
    p.x = static_cast<float>(d[3 * i]);
    p.y = static_cast<float>(d[3 * i + 1]);
    p.z = static_cast<float>(d[3 * i + 2]);
    finite += std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
    p.r = p.g = p.b = 128;
    p.a = 255;
    if (rgb.size()) {
      p.r = rgb.data()[3 * i];
      p.g = rgb.data()[3 * i + 1];
      p.b = rgb.data()[3 * i + 2];
    }
  }
  if (finite < 3)
    throw py::value_error("points: fewer than 3 finite points");
  return cloud;
}

/** camera=(fx, fy, cx, cy) as a pinhole camera (the image twice the principal point's size).
 * \throws py::value_error. */
facyl::PinholeCamera
cameraOf(const std::optional<std::vector<double>>& camera)
{
  if (!camera)
    return {};
  const auto& c = *camera;
  if (c.size() != 4 || !(c[0] > 0 && c[0] <= 1e5 && c[1] > 0 && c[1] <= 1e5 && c[2] >= 0 &&
                         c[2] <= 4000 && c[3] >= 0 && c[3] <= 4000))
    throw py::value_error("camera: expected (fx, fy, cx, cy) with 0 < fx, fy <= 1e5 and "
                          "0 <= cx, cy <= 4000 (pixels)");
  return {static_cast<float>(c[0]),
          static_cast<float>(c[1]),
          static_cast<float>(c[2]),
          static_cast<float>(c[3]),
          static_cast<int>(std::ceil(2 * c[2] + 1)),
          static_cast<int>(std::ceil(2 * c[3] + 1))};
}

/** A recognizer set up from detect()'s (and Tracker's) arguments: camera, up, model and the
 * recognizer's options (recognizerOptions) as keywords. \throws py::value_error. */
void
configureRecognizer(Recognizer& rec, const std::optional<std::vector<double>>& camera,
                    const py::object& up, const std::string& model, const py::kwargs& options)
{
  const facyl::PinholeCamera cam = cameraOf(camera);
  auto keywords = keywordList(options);
  keywords.emplace_back("up", up);
  keywords.emplace_back("model", py::str(model));
  facyl_cli::RecognizerSettings s;
  applyKeywords(facyl_cli::recognizerOptions(), keywords, s);
  facyl::ShapeClassifier::Ptr classifier;
  try {
    classifier = facyl_cli::classifierFor(s.model, facyl_cli::Vocabulary{true});
  }
  catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
  rec.setParameters(s.params);
  rec.setCamera(cam);
  rec.setClassifier(classifier);
  rec.setUpDirection(s.up);
}

/** The objects' point indices (rows of the flattened frame), added to \a out["objects"]. */
void
addIndices(py::object& out, const std::vector<facyl::RecognizedObject>& objects)
{
  py::list list = out["objects"];
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const auto& idx = objects[i].cluster.indices.indices;
    list[i]["indices"] =
      py::array_t<std::int64_t>(static_cast<py::ssize_t>(idx.size()),
                                std::vector<std::int64_t>(idx.begin(), idx.end()).data());
  }
}

py::object
detect(const py::object& points, const py::object& colors,
       const std::optional<std::vector<double>>& camera, const py::object& up,
       const std::string& model, const py::kwargs& options)
{
  bool organized = false;
  const RgbCloud::Ptr cloud = frameCloud(points, colors, organized);
  Recognizer rec;
  configureRecognizer(rec, camera, up, model, options);
  rec.setInputCloud(cloud);
  std::vector<facyl::RecognizedObject> objects;
  bool ok = false;
  {
    py::gil_scoped_release release;
    ok = rec.recognize(objects);
  }
  if (!ok)
    throw py::value_error("detect: recognition failed (see the message printed above)");
  // facyl_detect's fields, with the same meanings (floats exactly).
  py::object out =
    toPython(facyl_cli::sceneJson("", *cloud, rec, objects, rec.getTiming(), kPythonDigits));
  addIndices(out, objects);
  return out;
}

// ------------------------------------------------------------------------------ Tracker

/** facyl.Tracker: the recognizer and a CylinderTracker over the frames of one stream. */
class PyTracker {
public:
  PyTracker(const std::optional<std::vector<double>>& camera, const py::object& up,
            const std::string& model, const py::object& confirm_hits, const py::object& max_misses,
            const py::object& switch_frames, const py::kwargs& options)
  {
    configureRecognizer(rec_, camera, up, model, options);
    facyl::CylinderTrackerParameters tp;
    applyKeywords(facyl_cli::trackerOptions(),
                  {{"track_confirm_hits", confirm_hits},
                   {"track_max_misses", max_misses},
                   {"track_support_switch_frames", switch_frames}},
                  tp);
    tracker_.setParameters(tp);
    tracker_.setCamera(cameraOf(camera));
  }

  py::object update(const py::object& points, const py::object& colors)
  {
    bool organized = false;
    RgbCloud::Ptr cloud;
    try {
      cloud = frameCloud(points, colors, organized);
    }
    catch (...) { // a frame that cannot be used: the stream goes on, the tracks are kept
      skip();
      throw;
    }
    facyl_cli::Json json;
    bool ok = false;
    std::vector<facyl::RecognizedObject> objects;
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> lock(mutex_);
      rec_.setInputCloud(cloud);
      tracker_.prepare(rec_); // the tracks' table, where the camera's motion puts it
      ok = rec_.recognize(objects);
      if (ok) {
        tracker_.update(rec_, objects);
        json = facyl_cli::trackedSceneJson("", *cloud, rec_, objects, rec_.getTiming(), tracker_,
                                           kPythonDigits);
      }
      else
        tracker_.skipFrame();
    }
    if (!ok)
      throw py::value_error("Tracker.update: recognition failed (see the message printed above); "
                            "the frame is skipped, the tracks are kept");
    py::object out = toPython(json);
    addIndices(out, objects);
    return out;
  }

  void skip()
  {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(mutex_);
    tracker_.skipFrame();
  }

  void reset()
  {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(mutex_);
    tracker_.reset();
  }

  py::object tracks()
  {
    facyl_cli::Json frame = facyl_cli::Json::object();
    {
      py::gil_scoped_release release;
      std::lock_guard<std::mutex> lock(mutex_);
      facyl_cli::addStreamFields(frame, tracker_, nullptr, kPythonDigits);
    }
    return toPython(frame["tracks"]);
  }

  std::size_t frame()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return tracker_.getFrameInfo().frame;
  }

private:
  Recognizer rec_;
  facyl::CylinderTracker tracker_;
  std::mutex mutex_; ///< one update at a time (the GIL is released while it runs)
};

// ---------------------------------------------------------------------------- simulation

py::dict
simulateCylinder(double radius, double height, const std::vector<double>& axis,
                 const std::vector<double>& base, int points, double lid_ratio, double noise,
                 double occlusion, bool random_axis, long long seed)
{
  facyl::CylinderSimulationParameters p;
  p.radius = static_cast<float>(radius);
  p.height = static_cast<float>(height);
  if (axis.size() != 3 || base.size() != 3)
    throw py::value_error("axis and base: expected 3 numbers each");
  p.axis = Eigen::Vector3f(axis[0], axis[1], axis[2]);
  p.base = Eigen::Vector3f(base[0], base[1], base[2]);
  if (points < 10 || points > 10000000)
    throw py::value_error("points: must be in [10, 1e7]");
  p.lateral_points = static_cast<std::size_t>(points);
  p.lid_ratio = static_cast<float>(lid_ratio);
  p.noise = static_cast<float>(noise);
  p.occlusion = static_cast<float>(occlusion);
  p.random_axis = random_axis;
  if (seed < 0)
    throw py::value_error("seed: must be >= 0");
  p.seed = static_cast<std::uint64_t>(seed);
  const std::string why = facyl::validate(p);
  if (!why.empty())
    throw py::value_error(why);
  const facyl::SimulatedCylinder sim = facyl::simulateCylinder(p);
  const auto n = static_cast<py::ssize_t>(sim.cloud.size());
  py::array_t<float> xyz({n, py::ssize_t(3)}), normals({n, py::ssize_t(3)});
  py::array_t<bool> is_lid(n);
  auto x = xyz.mutable_unchecked<2>();
  auto nm = normals.mutable_unchecked<2>();
  auto lid = is_lid.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& q = sim.cloud[static_cast<std::size_t>(i)];
    x(i, 0) = q.x, x(i, 1) = q.y, x(i, 2) = q.z;
    nm(i, 0) = q.normal_x, nm(i, 1) = q.normal_y, nm(i, 2) = q.normal_z;
    lid(i) = sim.is_lid[static_cast<std::size_t>(i)] != 0;
  }
  py::dict truth;
  truth["base"] = vector3(sim.truth.base);
  truth["axis"] = vector3(sim.truth.axis);
  truth["radius"] = sim.truth.radius;
  truth["height"] = sim.truth.height;
  py::dict out;
  out["points"] = xyz;
  out["normals"] = normals;
  out["is_lid"] = is_lid;
  out["truth"] = truth;
  return out;
}

py::dict
renderTabletopScene(long long seed, const std::string& layout, const std::string& sensor)
{
  if (seed < 0)
    throw py::value_error("seed: must be >= 0");
  if (layout != "spread" && layout != "cluttered")
    throw py::value_error("layout: '" + layout + "' is not spread or cluttered");
  facyl::TabletopSceneParameters p =
    layout == "cluttered" ? facyl::clutteredSceneParameters() : facyl::TabletopSceneParameters{};
  if (!facyl::parseSensorPreset(sensor, p.sensor, p.camera))
    throw py::value_error("sensor: '" + sensor + "' is not kinect or stereo");
  p.seed = static_cast<std::uint64_t>(seed);
  facyl::RenderedScene scene;
  {
    py::gil_scoped_release release;
    scene = facyl::simulateTabletopScene(p);
  }
  const py::ssize_t h = scene.cloud.height, w = scene.cloud.width;
  py::array_t<float> xyz({h, w, py::ssize_t(3)});
  py::array_t<std::uint8_t> rgb({h, w, py::ssize_t(3)});
  py::array_t<std::uint16_t> ids({h, w});
  float* x = xyz.mutable_data();
  std::uint8_t* c = rgb.mutable_data();
  std::uint16_t* id = ids.mutable_data();
  for (std::size_t i = 0; i < scene.cloud.size(); ++i) {
    const auto& q = scene.cloud[i];
    x[3 * i] = q.x, x[3 * i + 1] = q.y, x[3 * i + 2] = q.z;
    c[3 * i] = q.r, c[3 * i + 1] = q.g, c[3 * i + 2] = q.b;
    id[i] = scene.object_id[i];
  }
  py::dict out;
  out["points"] = xyz;
  out["colors"] = rgb;
  out["object_id"] = ids;
  out["truth"] = py::module_::import("json").attr("loads")(facyl::groundTruthJson(scene));
  out["camera"] =
    std::vector<float>{scene.camera.fx, scene.camera.fy, scene.camera.cx, scene.camera.cy};
  return out;
}

py::dict
renderSequenceFrame(long long seed, long long frame, long long frames, const std::string& layout,
                    const std::string& sensor, const std::string& change, double orbit)
{
  if (seed < 0)
    throw py::value_error("seed: must be >= 0");
  if (frames < 2 || frames > 100000)
    throw py::value_error("frames: must be in [2, 100000]");
  if (frame < 0 || frame >= frames)
    throw py::value_error("frame: must be in [0, frames - 1]");
  if (layout != "spread" && layout != "cluttered")
    throw py::value_error("layout: '" + layout + "' is not spread or cluttered");
  facyl::TabletopSceneParameters p =
    layout == "cluttered" ? facyl::clutteredSceneParameters() : facyl::TabletopSceneParameters{};
  if (sensor == "random" || !facyl::parseSensorPreset(sensor, p.sensor, p.camera))
    throw py::value_error("sensor: '" + sensor + "' is not kinect or stereo");
  facyl::TabletopSequenceParameters sp;
  sp.frames = static_cast<std::size_t>(frames);
  sp.orbit = static_cast<float>(orbit);
  if (!facyl::parseSequenceChange(change, sp.change))
    throw py::value_error("change: '" + change + "' is not none, remove or add");
  const std::string why = facyl::validate(sp);
  if (!why.empty())
    throw py::value_error(why);
  p.seed = static_cast<std::uint64_t>(seed);
  facyl::RenderedScene scene;
  std::string sequence;
  {
    py::gil_scoped_release release;
    const facyl::TabletopSequence seq = facyl::generateTabletopSequence(p, sp);
    scene =
      facyl::renderSequenceFrame(seq, static_cast<std::size_t>(frame), p.camera, p.sensor,
                                 facyl::sequenceFrameSeed(p.seed, static_cast<std::size_t>(frame)));
    sequence = facyl::sequenceJson(seq);
  }
  const py::ssize_t h = scene.cloud.height, w = scene.cloud.width;
  py::array_t<float> xyz({h, w, py::ssize_t(3)});
  py::array_t<std::uint8_t> rgb({h, w, py::ssize_t(3)});
  py::array_t<std::uint16_t> ids({h, w});
  float* x = xyz.mutable_data();
  std::uint8_t* c = rgb.mutable_data();
  std::uint16_t* id = ids.mutable_data();
  for (std::size_t i = 0; i < scene.cloud.size(); ++i) {
    const auto& q = scene.cloud[i];
    x[3 * i] = q.x, x[3 * i + 1] = q.y, x[3 * i + 2] = q.z;
    c[3 * i] = q.r, c[3 * i + 1] = q.g, c[3 * i + 2] = q.b;
    id[i] = scene.object_id[i];
  }
  py::dict out;
  out["points"] = xyz;
  out["colors"] = rgb;
  out["object_id"] = ids;
  out["truth"] = py::module_::import("json").attr("loads")(facyl::groundTruthJson(scene));
  out["sequence"] = py::module_::import("json").attr("loads")(sequence);
  out["camera"] =
    std::vector<float>{scene.camera.fx, scene.camera.fy, scene.camera.cx, scene.camera.cy};
  return out;
}

/** \a text (an option's help value, as the tools write it) as Python writes it. */
std::string
pythonValue(facyl_cli::ValueKind kind, const std::string& text)
{
  switch (kind) {
  case ValueKind::Word:
    return "\"" + text + "\"";
  case ValueKind::Pair:
  case ValueKind::Vector3: {
    std::string out = "(" + text + ")";
    for (std::size_t at = out.find(','); at != std::string::npos; at = out.find(',', at + 2))
      out.insert(at + 1, " ");
    return out;
  }
  default:
    return text;
  }
}

/** "name=default, ...; switches (True gives one): name, ..." of the keywords \a table gives
 * Python but \a skipped, the defaults those of \a defaults where the help prints them (a word:
 * always), else None. */
template <typename S>
std::string
keywordDefaults(const facyl_cli::SettingsTable<S>& table, const S& defaults,
                const std::set<std::string>& skipped = {})
{
  const facyl_cli::Vocabulary say{true};
  std::string values, switches;
  for (const auto& o : table.options) {
    if (o.tool_only || skipped.count(o.name))
      continue;
    if (o.kind == ValueKind::Switch) {
      switches += (switches.empty() ? "" : ", ") + say.option(o.name);
      continue;
    }
    const bool printed = o.kind == ValueKind::Word || o.help.find("{}") != std::string::npos;
    values += (values.empty() ? "" : ", ") + say.option(o.name) + "=" +
              (printed ? pythonValue(o.kind, o.show(defaults)) : "None");
  }
  return values + "; switches (True gives one): " + switches;
}

std::string
fitDoc(const FitSettings& d)
{
  const auto& table = facyl_cli::fitOptions();
  const auto value = [&](const char* name) {
    const auto* o = table.find(name);
    return pythonValue(o->kind, o->show(d));
  };
  return R"(Fits up to max_cylinders cylinders to points (N, 3), one after another: facyl_fit's fit,
with facyl_fit's options under the same names ('_' for '-') and the same defaults.

The two-step Hough estimator: normals and principal curvatures of the neighbours nearest
points (unless normals (N, 3) are given), orientation votes weighted by curvature
(voting="soft-curvature", paper eq. 3; "soft-normal"; "rabbani": hard votes), a circle Hough
for position and radius, least-squares refinement.

points, normals: numpy arrays (N, 3) or Open3D Vector3dVector (pcd.points, pcd.normals).
radius_limits: (min, max), or "auto" (default None: "auto"): 0 to twice the extent of the
data across each candidate axis, HoughCylinderEstimation's own (pipes, tanks, cans; detect()
keeps (0.01, 0.25)). up: gravity's opposite in the cloud's frame (default None: unknown). prior:
orientation prior "uniform", "vertical", "vertical-strong" or "horizontal" about up ()" +
         pythonValue(ValueKind::Vector3, facyl_cli::shownVector(d.up)) +
         R"(
when not given); default None: "vertical" when up is given, else )" +
         value("prior") + R"( (detect() knows
the table: vertical in its frame). neighbours: k of the normal and curvature estimation
(default )" +
         value("neighbours") +
         R"(; k= is its old spelling). orientations: accumulator cells N_d ()" +
         value("orientations") + R"().
accumulators: independent accumulators ()" +
         value("accumulators") + R"(). distance_threshold: inlier distance (default
None: estimated from the residuals). outward_normals: inliers' normals must point away from
the axis (default False; any_normal_sign=True says the default). point_candidates:
candidates refined and compared on the points (0: the best alone, as facyl 0.1). coarse_scale:
at high noise, cues again from neighbours within this many radii (0: never). method: "facyl",
or "pcl-ransac" (PCL's SACSegmentationFromNormals on the same normals, for comparison). seed:
seed of the randomized accumulator (same seed, same result).
units: facyl works in metres. "auto" (default): metres, and a cloud evidently in millimetres
(spanning more than )" +
         facyl_cli::compactNumber(facyl_cli::kMaxMetreExtent) +
         R"( units) or radius limits beyond 1 raise ValueError; "m": metres, no
check; "mm": points, lengths given and results in millimetres (converted to metres for the
fit and back).
Every keyword and its default: )" +
         keywordDefaults(table, d) + R"(.
Returns a list of Cylinder, best first; empty when no cylinder is found (with a UserWarning that
says why: the radius limits exclude the cylinder there, too few points, ...). Raises
ValueError for an unknown keyword or a bad value, TypeError for a value of the wrong type.)";
}

std::string
detectDoc()
{
  return R"(The tabletop pipeline of facyl_detect on one frame: table, objects on it, cylinders.

points: an organized frame (H, W, 3) in the camera frame (x right, y down, z forward; NaN
where the sensor has no depth; metres), or (N, 3) with camera=(fx, fy, cx, cy) for the
objects' pixel boxes. colors: uint8 RGB of the same shape, optional. up: gravity's opposite,
optional. model: "default" (the shipped shape classifier), "none", or a path to an .onnx with
its .cfg. Any other keyword is one of facyl_detect's recognizer options with '_' for '-'
(the same checks; facyl_detect -h says what each does); their defaults: )" +
         keywordDefaults(facyl_cli::recognizerOptions(), facyl_cli::RecognizerSettings{},
                         {"model", "up"}) +
         R"(.
Returns facyl_detect's JSON object as a dict, the same fields with the same meanings:
"organized", "table" {"coefficients": [a, b, c, d] of the table plane in the cloud's frame
with a unit normal towards the sensor, or None; "found"}, "supports", "objects" (each with
"cylinder": the fields of Cylinder.as_dict(), or None), "timing_ms"; objects also carry
"indices" (int64 rows of the flattened frame). A frame without any support is not an error:
"table" then has "found" False and coefficients None, "supports" is empty and the objects have
support -1. Raises ValueError for bad input.)";
}

} // namespace

PYBIND11_MODULE(facyl, m)
{
  m.doc() = "facyl: fast cylinder detection (Figueiredo et al., RAS 2019) for numpy and Open3D.\n\n"
            "Arrays are float32 or float64 of shape (N, 3) (frames: (H, W, 3); float16 raises "
            "TypeError: convert it), or Open3D Vector3dVector; metres (fit_cylinders: units=\"mm\" "
            "converts); NaN rows are missing "
            "points. Keywords are the tools' option names with '_' for '-', with their defaults. "
            "Functions release the GIL while they compute.";
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);

  py::class_<PyCylinder>(m, "Cylinder", "A fitted finite cylinder (metres).")
    .def_property_readonly(
      "point_on_axis", [](const PyCylinder& c) { return vector3(c.model.point_on_axis); },
      "(3,) float32: a point on the axis (the base centre)")
    .def_property_readonly(
      "axis", [](const PyCylinder& c) { return vector3(c.model.axis); },
      "(3,) float32: unit axis, base to top")
    .def_property_readonly(
      "radius", [](const PyCylinder& c) { return c.model.radius; },
      "radius (the cloud's units: metres)")
    .def_property_readonly(
      "height", [](const PyCylinder& c) { return c.model.height; }, "|top - base|")
    .def_property_readonly(
      "base", [](const PyCylinder& c) { return vector3(c.model.base); },
      "(3,) float32: centre of the lowest inlier section")
    .def_property_readonly(
      "top", [](const PyCylinder& c) { return vector3(c.model.top); },
      "(3,) float32: centre of the highest inlier section")
    .def_property_readonly(
      "inliers",
      [](const PyCylinder& c) {
        std::vector<std::int64_t> v(c.model.inliers.begin(), c.model.inliers.end());
        return py::array_t<std::int64_t>(static_cast<py::ssize_t>(v.size()), v.data());
      },
      "(K,) int64: row indices of the inliers in points, ascending")
    .def_property_readonly(
      "n_inliers", [](const PyCylinder& c) { return c.model.inliers.size(); },
      "number of inliers (len(inliers))")
    .def_property_readonly(
      "inlier_ratio", [](const PyCylinder& c) { return c.model.inlier_ratio; },
      "inliers / rows given (paper eq. 4)")
    .def_property_readonly(
      "confidence", [](const PyCylinder& c) { return c.model.confidence; },
      "share of the orientation evidence its inliers carry, in [0, 1]")
    .def_property_readonly(
      "rms_error", [](const PyCylinder& c) { return c.model.rms_error; },
      "RMS distance of the inliers to the surface")
    .def_property_readonly(
      "angular_coverage", [](const PyCylinder& c) { return c.model.angular_coverage; },
      "share of the circumference with inliers")
    .def_property_readonly(
      "coefficients",
      [](const PyCylinder& c) {
        pcl::ModelCoefficients mc;
        c.model.toCoefficients(mc);
        return py::array_t<float>(7, mc.values.data());
      },
      "(7,) float32: PCL's SACMODEL_CYLINDER layout (point on axis, axis direction, radius)")
    .def(
      "as_dict",
      [](const PyCylinder& c) {
        return toPython(facyl_cli::cylinderObject(c.model, false, kPythonDigits));
      },
      "The fields facyl_fit prints for this cylinder (no inlier indices), as a dict.")
    .def("__repr__", [](const PyCylinder& c) {
      const auto& m = c.model;
      char buf[256];
      std::snprintf(buf, sizeof buf,
                    "Cylinder(radius=%.4f, height=%.4f, axis=[%.3f, %.3f, %.3f], "
                    "point_on_axis=[%.3f, %.3f, %.3f], inliers=%zu)",
                    m.radius, m.height, m.axis.x(), m.axis.y(), m.axis.z(), m.point_on_axis.x(),
                    m.point_on_axis.y(), m.point_on_axis.z(), m.inliers.size());
      return std::string(buf);
    });

  const FitSettings fit; // the defaults' one home
  m.def(
    "fit_cylinders",
    [](const py::object& points, const py::object& normals, const py::kwargs& options) {
      return fitCylinders(points, normals, keywordList(options));
    },
    py::arg("points"), py::arg("normals") = py::none(), fitDoc(fit).c_str());

  m.def(
    "estimate_normals_curvatures", &estimateNormalsCurvatures, py::arg("points"),
    py::arg("neighbours") = fit.neighbours, py::kw_only(), py::arg("k") = py::none(),
    (R"(Normals and principal curvatures of points (N, 3) from their nearest neighbours
(default )" +
     std::to_string(fit.neighbours) +
     R"(; k= is the old spelling), in one pass (facyl's NormalCurvatureEstimation). Returns (normals (N, 3),
principal_directions (N, 3), k_max (N,), k_min (N,)) as float32: unit normals, the unit
direction of largest normal change, and k_max >= k_min >= 0, the eigenvalues of the covariance
of the neighbours' normals projected on the tangent plane (PCL's pc1, pc2: dimensionless,
larger for tighter bends). NaN rows for points without a usable neighbourhood.)")
      .c_str());

  m.def("detect", &detect, py::arg("points"), py::arg("colors") = py::none(), py::kw_only(),
        py::arg("camera") = py::none(), py::arg("up") = py::none(),
        py::arg("model") = facyl_cli::RecognizerSettings{}.model, detectDoc().c_str());

  const facyl::CylinderSimulationParameters sim; // the defaults' one home
  const auto shown = [](float v) { return std::round(1e6 * static_cast<double>(v)) / 1e6; };
  m.def("simulate_cylinder", &simulateCylinder, py::kw_only(),
        py::arg("radius") = shown(sim.radius), py::arg("height") = shown(sim.height),
        py::arg("axis") =
          std::vector<double>{shown(sim.axis.x()), shown(sim.axis.y()), shown(sim.axis.z())},
        py::arg("base") =
          std::vector<double>{shown(sim.base.x()), shown(sim.base.y()), shown(sim.base.z())},
        py::arg("points") = sim.lateral_points, py::arg("lid_ratio") = shown(sim.lid_ratio),
        py::arg("noise") = shown(sim.noise), py::arg("occlusion") = shown(sim.occlusion),
        py::arg("random_axis") = sim.random_axis, py::arg("seed") = sim.seed,
        R"(A simulated cylinder (paper III-D1): points on the lateral surface (points = |P|), lid
outliers (lid_ratio, eq. 5), noise (relative to the radius), occlusion (eq. 6, a removed
sector). Returns {"points": (N, 3), "normals": (N, 3), "is_lid": (N,), "truth": {...}}.)");

  m.def("render_tabletop_scene", &renderTabletopScene, py::kw_only(), py::arg("seed") = 0,
        py::arg("layout") = "spread", py::arg("sensor") = "kinect",
        R"(A simulated RGB-D tabletop frame (facyl_synth): layout "spread" or "cluttered", sensor
"kinect" or "stereo". Returns {"points": (480, 640, 3) float32 (NaN without depth), "colors":
(480, 640, 3) uint8, "object_id": (480, 640) uint16 (0 background, 1 table, 2+ objects),
"truth": the ground truth (dict), "camera": [fx, fy, cx, cy]}.)");

  m.def("render_sequence_frame", &renderSequenceFrame, py::kw_only(), py::arg("seed") = 0,
        py::arg("frame") = 0, py::arg("frames") = 30, py::arg("layout") = "cluttered",
        py::arg("sensor") = "kinect", py::arg("change") = "none", py::arg("orbit") = 0.9,
        R"(Frame `frame` of a simulated stream (facyl_synth --sequence): a camera moving along a
smooth path around a static table of `layout` ("cluttered" or "spread"), seen by `sensor`
("kinect" or "stereo"), `frames` frames turning by `orbit` rad; change "remove" / "add" takes
an object away / puts one down half-way. The same keys as render_tabletop_scene (object_id:
2 + i is the sequence's object i in every frame), plus "sequence": the change and, per frame,
the camera pose and the object ids present.)");

  py::class_<PyTracker>(m, "Tracker",
                        R"(Objects and cylinders tracked across the frames of one stream
(facyl_detect --track; C++ facyl::CylinderTracker): a camera moving over a static table.

Tracker(camera=None, up=None, model="default", track_confirm_hits=2, track_max_misses=5,
track_support_switch_frames=3, **options): camera, up, model and the other keywords as in detect() (facyl_detect's recognizer
options, '_' for '-'); track_confirm_hits: frames a new track must be seen in before it is
confirmed (a cylinder seen in one frame only never becomes a track); track_max_misses: missed
frames a confirmed track survives (occlusion; longer when the frame shows it hidden or out of
view); track_support_switch_frames: frames in a row another support must win before it replaces
the tracks' table (the last frames' table is handed to the recognizer as its support prior).
update() is serialised: one frame at a time, from any thread (the GIL is released).)")
    .def(py::init<const std::optional<std::vector<double>>&, const py::object&, const std::string&,
                  const py::object&, const py::object&, const py::object&, const py::kwargs&>(),
         py::kw_only(), py::arg("camera") = py::none(), py::arg("up") = py::none(),
         py::arg("model") = facyl_cli::RecognizerSettings{}.model,
         py::arg("track_confirm_hits") = facyl::CylinderTrackerParameters{}.confirm_hits,
         py::arg("track_max_misses") = facyl::CylinderTrackerParameters{}.max_misses,
         py::arg("track_support_switch_frames") =
           facyl::CylinderTrackerParameters{}.support_switch_frames)
    .def("update", &PyTracker::update, py::arg("points"), py::arg("colors") = py::none(),
         R"(The next frame of the stream (points and colors as for detect()). Returns facyl_detect
--track's JSON line as a dict: detect()'s fields, with per object "track_id" (int, stable across
frames), "is_cylinder" and "cylinder" the track's decision and filtered estimate in this frame,
"is_cylinder_frame" and "cylinder_frame" the frame's own, "role", "merged", "track" (its state),
"indices"; and "stream" (frame, scene, anchored, ...) and "tracks" (every live track). A frame
that cannot be used raises ValueError and is skipped: the tracks are kept.)")
    .def("skip", &PyTracker::skip,
         "A frame that could not be had (dropped, unreadable): counted, the tracks are kept.")
    .def("reset", &PyTracker::reset, "Ends every track (a new stream); ids go on.")
    .def_property_readonly("tracks", &PyTracker::tracks,
                           "The live tracks (list of dicts: track_id, object, merged_into, state, "
                           "centroid, cylinder in the last frame).")
    .def_property_readonly("frame", &PyTracker::frame, "Frames given (update() and skip()).");

  m.def("_time_fit_in_cpp", &timeFitInCpp, py::arg("points"), py::arg("repeats") = 50,
        py::arg("k") = fit.neighbours,
        "Median ms of fit_cylinders' C++ work (default settings) repeated inside C++: the "
        "reference for the binding's overhead.");
  m.attr("__version__") = FACYL_VERSION;
}
