/*
 * facyl: fast cylinder detection for PCL.
 * CylinderClassifier: OpenCV DNN stays in this file.
 */
#include <facyl/recognition/cylinder_classifier.h>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include <algorithm>
#include <cmath>
#include <dlfcn.h>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <sys/stat.h>
#include <vector>

namespace facyl {

std::string
parseClassifierModelInfo(const std::string& text, ClassifierModelInfo& info)
{
  ClassifierModelInfo out;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  bool seen_channels = false, seen_size = false;
  while (std::getline(lines, line)) {
    ++number;
    const auto hash = line.find('#');
    if (hash != std::string::npos)
      line.erase(hash);
    std::istringstream in(line);
    std::string key;
    if (!(in >> key))
      continue;
    const std::string where = "line " + std::to_string(number) + " (" + key + "): ";
    if (key == "channels") {
      std::string value;
      if (!(in >> value) || !parseClassifierChannels(value, out.input.channels))
        return where + "expected rgb, depth or depthrgb";
      seen_channels = true;
    }
    else if (key == "size") {
      if (!(in >> out.input.size) || out.input.size < 8 || out.input.size > 512)
        return where + "expected an integer in [8, 512]";
      seen_size = true;
    }
    else if (key == "mean") {
      if (!(in >> out.mean) || !std::isfinite(out.mean))
        return where + "expected a number";
    }
    else if (key == "scale") {
      if (!(in >> out.scale) || !std::isfinite(out.scale) || out.scale == 0.f)
        return where + "expected a finite non-zero number";
    }
    else if (key == "output") {
      std::string value;
      in >> value;
      if (value != "softmax" && value != "sigmoid")
        return where + "expected softmax or sigmoid";
      out.softmax = value == "softmax";
    }
    else if (key == "fusion") {
      std::vector<float> w;
      for (float v; in >> v;)
        w.push_back(v);
      const bool all = w.size() == kEvidenceFeatures, side = w.size() == kSideOnlyEvidenceFeatures;
      if (!in.eof() || !(all || side) ||
          !std::all_of(w.begin(), w.end(), [](float v) { return std::isfinite(v); }))
        return where + "expected " + std::to_string(kEvidenceFeatures) + " (or " +
               std::to_string(kSideOnlyEvidenceFeatures) +
               ", fitted before lid fits) finite numbers (the evidence model of "
               "recognition/training/fit_evidence.py)";
      // A model fitted before lid fits: its side's weights and the network's.
      out.fusion.fill(0.f);
      std::copy(w.begin(), w.begin() + (all ? kEvidenceFeatures : kLidFeaturesBegin),
                out.fusion.begin());
      out.fusion.back() = w.back();
      out.has_fusion = true;
      out.has_lid_fusion = all;
    }
    else
      return where + "unknown key";
    std::string extra;
    if (in >> extra)
      return where + "unexpected '" + extra + "'";
  }
  if (!seen_channels || !seen_size)
    return "'channels' and 'size' are required";
  info = out;
  return {};
}

struct CylinderClassifier::Network {
  cv::dnn::Net net;
};

CylinderClassifier::CylinderClassifier() = default;
CylinderClassifier::~CylinderClassifier() = default;

namespace {

bool
isRegularFile(const std::string& path)
{
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string
readText(const std::string& path, const std::string& call)
{
  if (!isRegularFile(path))
    throw std::runtime_error(call + " " + path + ": no such file");
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  if (!in && !in.eof())
    throw std::runtime_error(call + " " + path + ": cannot read");
  return s.str();
}

} // namespace

void
CylinderClassifier::load(const std::string& onnx_path)
{
  const std::string call = "[facyl::CylinderClassifier::load]";
  net_.reset();
  const auto dot = onnx_path.find_last_of('.');
  const auto slash = onnx_path.find_last_of('/');
  const std::string stem = (dot == std::string::npos || (slash != std::string::npos && dot < slash))
                             ? onnx_path
                             : onnx_path.substr(0, dot);
  const std::string cfg = stem + ".cfg";
  // The model first: a wrong path is named as given, not by the description beside it.
  if (!isRegularFile(onnx_path))
    throw std::runtime_error(call + " " + onnx_path + ": no such file");
  const std::string why = parseClassifierModelInfo(readText(cfg, call), info_);
  if (!why.empty())
    throw std::runtime_error(call + " " + cfg + ": " + why);
  auto network = std::make_unique<Network>();
  try {
    network->net = cv::dnn::readNetFromONNX(onnx_path);
  }
  catch (const cv::Exception& e) {
    throw std::runtime_error(call + " " + onnx_path +
                             ": OpenCV cannot read it as an ONNX network (truncated or not "
                             "ONNX?): " +
                             e.err);
  }
  net_ = std::move(network);
  name_ = "cnn:" + onnx_path;
  check(call + " " + onnx_path);
}

void
CylinderClassifier::loadCaffe(const std::string& prototxt, const std::string& caffemodel,
                              const std::string& cfg_path)
{
  const std::string call = "[facyl::CylinderClassifier::loadCaffe]";
  net_.reset();
  const std::string why = parseClassifierModelInfo(readText(cfg_path, call), info_);
  if (!why.empty())
    throw std::runtime_error(call + " " + cfg_path + ": " + why);
  for (const auto& f : {prototxt, caffemodel})
    if (!isRegularFile(f))
      throw std::runtime_error(call + " " + f + ": no such file");
  auto network = std::make_unique<Network>();
  try {
    network->net = cv::dnn::readNetFromCaffe(prototxt, caffemodel);
  }
  catch (const cv::Exception& e) {
    throw std::runtime_error(call + " " + prototxt + ", " + caffemodel +
                             ": OpenCV cannot read them as a Caffe network: " + e.err);
  }
  net_ = std::move(network);
  name_ = "cnn:" + caffemodel;
  check(call + " " + caffemodel);
}

void
CylinderClassifier::check(const std::string& what)
{
  // One all-zero input of the described shape: the network must take it and give 1 or 2
  // outputs per view.
  const int c = channelCount(info_.input.channels), s = info_.input.size;
  std::vector<std::uint8_t> zeros(static_cast<std::size_t>(c * s * s), 0);
  const int expected = info_.softmax ? 2 : 1;
  try {
    const int sizes[] = {2, c, s, s};
    cv::Mat blob(4, sizes, CV_32F, cv::Scalar(0));
    net_->net.setInput(blob);
    const cv::Mat out = net_->net.forward();
    if (out.total() != static_cast<std::size_t>(2 * expected)) {
      std::ostringstream m;
      m << what << ": the network gives " << out.total() / 2 << " outputs per view; the "
        << "description says " << expected << " (output " << (info_.softmax ? "softmax" : "sigmoid")
        << ")";
      net_.reset();
      throw std::runtime_error(m.str());
    }
  }
  catch (const cv::Exception& e) {
    net_.reset();
    std::ostringstream m;
    m << what << ": the network does not take the described input (" << c << " x " << s << " x "
      << s << ", channels " << toString(info_.input.channels) << "): " << e.err;
    throw std::runtime_error(m.str());
  }
}

bool
CylinderClassifier::loaded() const
{
  return static_cast<bool>(net_);
}

std::string
CylinderClassifier::defaultModelPath()
{
  // An installed library finds the model beside it (<prefix>/lib/../share/facyl/models, also
  // after the prefix was moved); the build tree finds the source tree's.
  std::vector<std::string> dirs;
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&CylinderClassifier::defaultModelPath), &info) != 0 &&
      info.dli_fname != nullptr) {
    const std::string lib = info.dli_fname;
    const auto slash = lib.find_last_of('/');
    if (slash != std::string::npos)
      dirs.push_back(lib.substr(0, slash) + "/../share/facyl/models");
  }
  dirs.emplace_back(FACYL_SOURCE_MODEL_DIR);
  dirs.emplace_back(FACYL_INSTALL_MODEL_DIR);
  for (const std::string& dir : dirs) {
    const std::string path = dir + "/cylinder_net.onnx";
    if (isRegularFile(path))
      return path;
  }
  return {};
}

std::vector<float>
CylinderClassifier::probabilitiesOfImages(const std::vector<std::vector<std::uint8_t>>& images)
{
  if (!net_)
    throw std::logic_error("[facyl::CylinderClassifier] no model loaded (call load first)");
  const int c = channelCount(info_.input.channels), s = info_.input.size;
  const std::size_t per = static_cast<std::size_t>(c * s * s);
  std::vector<float> p(images.size(), std::numeric_limits<float>::quiet_NaN());
  std::vector<std::size_t> usable;
  for (std::size_t k = 0; k < images.size(); ++k)
    if (images[k].size() == per)
      usable.push_back(k);
  if (usable.empty())
    return p;
  const int sizes[] = {static_cast<int>(usable.size()), c, s, s};
  cv::Mat blob(4, sizes, CV_32F);
  float* dst = blob.ptr<float>();
  for (const std::size_t k : usable)
    for (const std::uint8_t b : images[k])
      *dst++ = (static_cast<float>(b) - info_.mean) * info_.scale;
  net_->net.setInput(blob);
  const cv::Mat out = net_->net.forward();
  const float* o = out.ptr<float>();
  for (std::size_t j = 0; j < usable.size(); ++j) {
    float q;
    if (info_.softmax) {
      const float a = o[2 * j], b = o[2 * j + 1];
      q = 1.f / (1.f + std::exp(a - b));
    }
    else
      q = 1.f / (1.f + std::exp(-o[j]));
    p[usable[j]] = q;
  }
  return p;
}

std::vector<float>
CylinderClassifier::cylinderProbabilities(const std::vector<ObjectView>& views)
{
  std::vector<std::vector<std::uint8_t>> images;
  images.reserve(views.size());
  for (const auto& v : views)
    images.push_back(classifierImage(v, info_.input));
  return probabilitiesOfImages(images);
}

float
CylinderClassifier::cylinderProbability(const ObjectView& view)
{
  return cylinderProbabilities({view}).front();
}

float
CylinderClassifier::fuse(float p_network, const CylinderEvidence& evidence,
                         const CylinderDecision& decision) const
{
  if (!std::isfinite(p_network))
    return geometricProbability(evidence, decision);
  if (!info_.has_fusion)
    return p_network;
  if (evidence.from_lid && !info_.has_lid_fusion)
    return geometricProbability(evidence, decision);
  return evidenceProbability(info_.fusion, p_network, evidence);
}

std::string
CylinderClassifier::name() const
{
  return name_.empty() ? "cnn (not loaded)" : name_;
}

} // namespace facyl
