/*
 * facyl: the shape classifier (paper III-B): its input images, the model description, the
 * shipped model on simulated crops it never saw, clear errors for bad models, the fusion and
 * the recognizer with the classifier.
 */
#include <facyl/recognition/classifier_input.h>
#include <facyl/recognition/cylinder_classifier.h>
#include <facyl/recognition/tabletop_cylinder_recognizer.h>
#include <facyl/simulation/tabletop_scene.h>

#include <pcl/io/pcd_io.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZRGBA>;

/** An organized 40 x 30 cloud whose pixels [10, 30) x [5, 25) see a cylinder of radius 5 cm
 * 1 m away (axis along y), the rest nothing. */
Cloud::Ptr
cylinderPatch(std::vector<int>& indices)
{
  Cloud::Ptr cloud(new Cloud(40, 30));
  for (int v = 0; v < 30; ++v)
    for (int u = 0; u < 40; ++u) {
      auto& p = cloud->at(u, v);
      p.x = p.y = p.z = std::numeric_limits<float>::quiet_NaN();
      p.r = p.g = p.b = 10;
      if (u >= 10 && u < 30 && v >= 5 && v < 25) {
        const float x = 0.005f * static_cast<float>(u - 20);
        p.x = x;
        p.y = 0.005f * static_cast<float>(v - 15);
        p.z = 1.f - std::sqrt(std::max(0.f, 0.05f * 0.05f - x * x));
        p.r = 200;
        indices.push_back(v * 40 + u);
      }
    }
  cloud->is_dense = false;
  return cloud;
}

std::string
writeFile(const std::string& name, const std::string& text)
{
  const auto path = std::filesystem::temp_directory_path() / ("facyl_test_classifier_" + name);
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

std::string
readFile(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

} // namespace

// ------------------------------------------------------------------------- input images

TEST(ClassifierInput, ViewOfAnOrganizedCluster)
{
  std::vector<int> idx;
  const Cloud::Ptr cloud = cylinderPatch(idx);
  const facyl::ObjectView view = facyl::objectView(*cloud, idx, facyl::PinholeCamera{});
  EXPECT_EQ(view.box, (facyl::PixelBox{10, 5, 29, 24}));
  ASSERT_EQ(view.pixels.cols(), static_cast<Eigen::Index>(idx.size()));
  EXPECT_EQ(view.pixels(0, 0), 10);
  EXPECT_EQ(view.pixels(1, 0), 5);
  EXPECT_EQ(view.crop.width, 20);
  EXPECT_EQ(view.crop.height, 20);
  EXPECT_EQ(view.crop.data[0], 200);
}

TEST(ClassifierInput, DepthImageHasTheMaskAndTheRelativeDepth)
{
  std::vector<int> idx;
  const Cloud::Ptr cloud = cylinderPatch(idx);
  const facyl::ObjectView view = facyl::objectView(*cloud, idx, facyl::PinholeCamera{});
  const auto image = facyl::classifierImage(view, {facyl::ClassifierChannels::Depth, 16});
  ASSERT_EQ(image.size(), 2u * 16 * 16);
  // The box is square: every pixel is the object's.
  for (int i = 0; i < 256; ++i)
    ASSERT_EQ(image[static_cast<std::size_t>(i)], 255) << i;
  // Nearer in the middle column (the cylinder's front), farther at the sides.
  const auto depth = [&](int x, int y) {
    return image[256 + static_cast<std::size_t>(y * 16 + x)];
  };
  EXPECT_LT(depth(8, 8), depth(0, 8));
  EXPECT_LT(depth(8, 8), depth(15, 8));
  EXPECT_EQ(depth(3, 2), depth(3, 13)); // constant along the axis
  // A view without pixels or a box gives nothing.
  facyl::ObjectView empty;
  EXPECT_TRUE(facyl::classifierImage(empty, {facyl::ClassifierChannels::Depth, 16}).empty());
  EXPECT_TRUE(facyl::classifierImage(empty, {facyl::ClassifierChannels::Rgb, 16}).empty());
  EXPECT_TRUE(facyl::classifierImage(view, {facyl::ClassifierChannels::Depth, 4}).empty());
}

TEST(ClassifierInput, DepthImageSamplesTheSquaresPixelCentres)
{
  // Against the definition (the square's depth per pixel, the last point on a pixel winning,
  // sampled at size x size pixel centres): a box smaller than the image (each pixel sampled
  // several times), one larger (pixels skipped), a tall one (padded), points on the same
  // pixel, holes.
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> z01(0.8f, 1.2f);
  for (const auto& [w, h] : {std::pair<int, int>{9, 9}, {150, 97}, {12, 40}}) {
    facyl::ObjectView view;
    std::vector<Eigen::Vector3f> points;
    std::vector<Eigen::Vector2i> pixels;
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) {
        if ((u * 7 + v * 3) % 11 == 0)
          continue; // holes
        for (int again = 0; again < ((u + v) % 5 == 0 ? 2 : 1); ++again) {
          points.emplace_back(0.001f * static_cast<float>(u), 0.001f * static_cast<float>(v),
                              z01(rng));
          pixels.emplace_back(100 + u, 50 + v);
        }
      }
    view.points.resize(3, static_cast<Eigen::Index>(points.size()));
    view.pixels.resize(2, static_cast<Eigen::Index>(points.size()));
    for (std::size_t k = 0; k < points.size(); ++k) {
      view.points.col(static_cast<Eigen::Index>(k)) = points[k];
      view.pixels.col(static_cast<Eigen::Index>(k)) = pixels[k];
    }
    facyl::viewBox(view);
    ASSERT_EQ(view.box, (facyl::PixelBox{100, 50, 100 + w - 1, 50 + h - 1}));
    const int size = 32;
    const auto image = facyl::classifierImage(view, {facyl::ClassifierChannels::Depth, size});
    ASSERT_EQ(image.size(), 2u * size * size);
    // The definition.
    const int side = std::max(w, h), u0 = 100 - (side - w) / 2, v0 = 50 - (side - h) / 2;
    std::vector<float> square(static_cast<std::size_t>(side * side),
                              std::numeric_limits<float>::quiet_NaN());
    std::vector<float> zs;
    float lo_x = 1e9f, lo_y = 1e9f, hi_x = -1e9f, hi_y = -1e9f;
    for (std::size_t k = 0; k < points.size(); ++k) {
      square[static_cast<std::size_t>((pixels[k].y() - v0) * side + pixels[k].x() - u0)] =
        points[k].z();
      zs.push_back(points[k].z());
      lo_x = std::min(lo_x, points[k].x());
      lo_y = std::min(lo_y, points[k].y());
      hi_x = std::max(hi_x, points[k].x());
      hi_y = std::max(hi_y, points[k].y());
    }
    std::nth_element(zs.begin(), zs.begin() + static_cast<std::ptrdiff_t>(zs.size() / 2), zs.end());
    const float median = zs[zs.size() / 2];
    const float extent = std::max(0.01f, std::max(hi_x - lo_x, hi_y - lo_y));
    const auto source = [&](int i) { return ((2 * i + 1) * side) / (2 * size); };
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const float d = square[static_cast<std::size_t>(source(y) * side + source(x))];
        const std::size_t o = static_cast<std::size_t>(y * size + x);
        const int mask = std::isfinite(d) ? 255 : 0;
        const int relative = std::isfinite(d)
                               ? static_cast<int>(std::lround(
                                   128.f + 127.f * std::clamp((d - median) / extent, -1.f, 1.f)))
                               : 128;
        ASSERT_EQ(image[o], mask) << w << " x " << h << " at " << x << ", " << y;
        ASSERT_EQ(image[static_cast<std::size_t>(size * size) + o], relative)
          << w << " x " << h << " at " << x << ", " << y;
      }
  }
}

TEST(ClassifierInput, ADepthModelGetsViewsWithoutTheCrop)
{
  std::vector<int> idx;
  const Cloud::Ptr cloud = cylinderPatch(idx);
  const facyl::ObjectView with = facyl::objectView(*cloud, idx, facyl::PinholeCamera{});
  const facyl::ObjectView without = facyl::objectView(*cloud, idx, facyl::PinholeCamera{}, false);
  EXPECT_FALSE(with.crop.empty());
  EXPECT_TRUE(without.crop.empty());
  EXPECT_EQ(without.box, with.box);
  const facyl::ClassifierInputSpec depth{facyl::ClassifierChannels::Depth, 64};
  EXPECT_EQ(facyl::classifierImage(without, depth), facyl::classifierImage(with, depth));
  // The shipped model reads depth only; a classifier that says nothing gets crops.
  facyl::CylinderClassifier shipped;
  EXPECT_TRUE(shipped.usesCrop()); // nothing loaded yet
  const std::string path = facyl::CylinderClassifier::defaultModelPath();
  ASSERT_FALSE(path.empty());
  shipped.load(path);
  EXPECT_FALSE(shipped.usesCrop());
}

TEST(ClassifierInput, RgbImageIsTheCropPaddedToASquare)
{
  std::vector<int> idx;
  Cloud::Ptr cloud = cylinderPatch(idx);
  // Only the upper half: a 20 x 10 box, padded to 20 x 20 about its centre.
  std::vector<int> half(idx.begin(), idx.begin() + 200);
  const facyl::ObjectView view = facyl::objectView(*cloud, half, facyl::PinholeCamera{});
  EXPECT_EQ(view.box, (facyl::PixelBox{10, 5, 29, 14}));
  const auto image = facyl::classifierImage(view, {facyl::ClassifierChannels::Rgb, 20});
  ASSERT_EQ(image.size(), 3u * 20 * 20);
  EXPECT_EQ(image[0], 0);                  // row 0: padding
  EXPECT_EQ(image[10 * 20 + 5], 200);      // row 10: the crop (red)
  EXPECT_EQ(image[400 + 10 * 20 + 5], 10); // green plane
}

TEST(ClassifierInput, DepthRgbImageIsTheDepthPlanesThenTheRgbPlanes)
{
  // facyl_crops writes depth.u8 and rgb.u8; train_classifier.py joins them into the depthrgb
  // input: that must be what the classifier makes of the same view.
  std::vector<int> idx;
  Cloud::Ptr cloud = cylinderPatch(idx);
  std::vector<int> half(idx.begin(), idx.begin() + 200);
  for (const auto& indices : {idx, half}) {
    const facyl::ObjectView view = facyl::objectView(*cloud, indices, facyl::PinholeCamera{});
    auto joined = facyl::classifierImage(view, {facyl::ClassifierChannels::Depth, 24});
    const auto rgb = facyl::classifierImage(view, {facyl::ClassifierChannels::Rgb, 24});
    ASSERT_FALSE(joined.empty());
    ASSERT_FALSE(rgb.empty());
    joined.insert(joined.end(), rgb.begin(), rgb.end());
    const auto image = facyl::classifierImage(view, {facyl::ClassifierChannels::DepthRgb, 24});
    ASSERT_EQ(image.size(), 5u * 24 * 24);
    EXPECT_EQ(image, joined);
  }
  // Without colour (no crop) or without pixels there is no input.
  facyl::ObjectView grey = facyl::objectView(*cloud, idx, facyl::PinholeCamera{});
  grey.crop = facyl::RgbImage{};
  EXPECT_TRUE(facyl::classifierImage(grey, {facyl::ClassifierChannels::DepthRgb, 24}).empty());
  EXPECT_TRUE(
    facyl::classifierImage(facyl::ObjectView{}, {facyl::ClassifierChannels::DepthRgb, 24}).empty());
  EXPECT_EQ(facyl::channelCount(facyl::ClassifierChannels::DepthRgb), 5);
  facyl::ClassifierChannels c = facyl::ClassifierChannels::Rgb;
  ASSERT_TRUE(facyl::parseClassifierChannels("depthrgb", c));
  EXPECT_EQ(c, facyl::ClassifierChannels::DepthRgb);
  EXPECT_EQ(facyl::toString(c), "depthrgb");
}

// ------------------------------------------------------------------ model description

TEST(CylinderClassifier, ModelDescriptionIsParsedStrictly)
{
  facyl::ClassifierModelInfo info;
  EXPECT_EQ(facyl::parseClassifierModelInfo("channels rgb\nsize 227 # the paper's\nmean 0\n"
                                            "scale 1\noutput sigmoid\n",
                                            info),
            "");
  EXPECT_EQ(info.input.channels, facyl::ClassifierChannels::Rgb);
  EXPECT_EQ(info.input.size, 227);
  EXPECT_FALSE(info.softmax);
  EXPECT_FALSE(info.has_fusion);
  EXPECT_EQ(facyl::parseClassifierModelInfo("channels depth\nsize 64\nfusion 1 2 3 4 5 6 7 8 9 10 "
                                            "11 12 13 14 15 16 17 18 19 20\n",
                                            info),
            "");
  EXPECT_TRUE(info.has_fusion);
  EXPECT_TRUE(info.has_lid_fusion);
  EXPECT_EQ(info.fusion[14], 15.f);
  EXPECT_EQ(info.fusion[19], 20.f);
  // A model fitted before lid fits: the side's weights and the network's, none for a lid.
  EXPECT_EQ(facyl::parseClassifierModelInfo(
              "channels depth\nsize 64\nfusion 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15\n", info),
            "");
  EXPECT_TRUE(info.has_fusion);
  EXPECT_FALSE(info.has_lid_fusion);
  EXPECT_EQ(info.fusion[13], 14.f);
  EXPECT_EQ(info.fusion[14], 0.f);
  EXPECT_EQ(info.fusion[18], 0.f);
  EXPECT_EQ(info.fusion[19], 15.f);
  EXPECT_EQ(facyl::parseClassifierModelInfo("channels depthrgb\nsize 64\n", info), "");
  EXPECT_EQ(info.input.channels, facyl::ClassifierChannels::DepthRgb);
  EXPECT_NE(facyl::parseClassifierModelInfo("size 64\n", info), "");
  EXPECT_NE(facyl::parseClassifierModelInfo("channels hsv\nsize 64\n", info).find("line 1"),
            std::string::npos);
  EXPECT_NE(facyl::parseClassifierModelInfo("channels rgb\nsize 4\n", info), "");
  EXPECT_NE(facyl::parseClassifierModelInfo("channels rgb\nsize 64\nfusion 1 2\n", info), "");
  // The evidence model of an older facyl (9 weights) is refused, naming what it expects.
  EXPECT_NE(
    facyl::parseClassifierModelInfo("channels rgb\nsize 64\nfusion 1 2 3 4 5 6 7 8 9\n", info)
      .find("expected 20 (or 15, fitted before lid fits) finite numbers"),
    std::string::npos);
  EXPECT_NE(facyl::parseClassifierModelInfo("channels rgb\nsize 64\nfusion 1 2 3 4 5 6 7 8 9 10 "
                                            "11 12 13 14 15 x\n",
                                            info),
            "");
  EXPECT_NE(
    facyl::parseClassifierModelInfo("channels rgb\nsize 64\nwidth 3\n", info).find("unknown key"),
    std::string::npos);
  EXPECT_NE(facyl::parseClassifierModelInfo("channels rgb 3\nsize 64\n", info), "");
}

TEST(CylinderEvidence, EvidenceFeaturesAndProbability)
{
  facyl::CylinderEvidence e;
  e.fitted = true;
  e.surface_ratio = 0.9f;
  e.inlier_ratio = 0.7f;
  e.angular_coverage = 0.4f;
  const auto f = facyl::evidenceFeatures(0.5f, e);
  EXPECT_EQ(f[0], 1.f);
  EXPECT_EQ(f[1], 0.9f);
  EXPECT_EQ(f[2], 0.7f);
  EXPECT_EQ(f[3], 1.f); // unknown curvature ratio
  EXPECT_EQ(f[7], 4.f); // unknown normal agreement: the worst
  EXPECT_EQ(f[8], 1.f); // unknown normal concentration: the worst
  EXPECT_EQ(f[9], 0.f); // unknown profile range: no evidence against
  const std::size_t net = facyl::kEvidenceFeatures - 1;           // the network's logit, last
  EXPECT_EQ(f[facyl::kLidFeaturesBegin], 0.f);                    // a side's fit: no lid features
  EXPECT_NEAR(f[net], 0.f, 1e-6f);                                // logit(0.5)
  EXPECT_EQ(facyl::evidenceFeatures(std::nanf(""), e)[net], 0.f); // no network
  std::array<float, facyl::kEvidenceFeatures> w{};
  w[net] = 1.f;
  EXPECT_NEAR(facyl::evidenceProbability(w, 0.8f, e), 0.8f, 1e-5f);
  w = {};
  w[1] = -2.f / 0.9f;
  EXPECT_NEAR(facyl::evidenceProbability(w, 0.8f, e), 1.f / (1.f + std::exp(2.f)), 1e-6f);
  EXPECT_TRUE(std::isfinite(facyl::evidenceFeatures(0.f, e)[net]));
  EXPECT_TRUE(std::isfinite(facyl::evidenceFeatures(1.f, e)[net]));
  // A bowl's inside (shallower than wide) against a cup's.
  e.shape.inner_share = 0.4f;
  e.shape.aspect = 0.25f;
  EXPECT_NEAR(facyl::evidenceFeatures(0.5f, e)[13], 0.3f, 1e-6f);
  e.shape.aspect = 1.5f;
  EXPECT_EQ(facyl::evidenceFeatures(0.5f, e)[13], 0.f);
}

TEST(CylinderEvidence, TheEvidenceModelDecidesAmongTheFitsThatPassTheGates)
{
  facyl::CylinderDecision d;
  facyl::CylinderEvidence e;
  EXPECT_FALSE(facyl::acceptCylinder(e, d)); // not fitted
  EXPECT_EQ(facyl::geometricProbability(e, d), 0.f);
  e.fitted = true;
  e.surface_ratio = e.inlier_ratio = 0.9f;
  e.angular_coverage = 0.4f;
  d.geometry_weights = {};
  d.geometry_weights[0] = 1.f; // p = 0.73 whatever the evidence
  EXPECT_TRUE(facyl::acceptGeometry(e, d));
  EXPECT_TRUE(facyl::acceptCylinder(e, d));
  e.p_cylinder = 0.2f; // known (a classifier's fusion): it decides
  EXPECT_FALSE(facyl::acceptCylinder(e, d));
  EXPECT_TRUE(facyl::acceptGeometry(e, d)); // the geometric decision alone
  e.p_cylinder = 0.9f;
  EXPECT_TRUE(facyl::acceptCylinder(e, d));
  e.surface_ratio = 0.2f; // a gate: the model is not asked
  EXPECT_FALSE(facyl::acceptCylinder(e, d));
  EXPECT_FALSE(facyl::passesGates(e, d));
  e.surface_ratio = 0.9f;
  d.geometry_weights[0] = -1.f;
  e.p_cylinder = std::nanf("");
  EXPECT_FALSE(facyl::acceptGeometry(e, d));
  EXPECT_FALSE(facyl::acceptCylinder(e, d));
}

// ------------------------------------------------------------------------ the model

TEST(CylinderClassifier, ShippedModelLoads)
{
  const std::string path = facyl::CylinderClassifier::defaultModelPath();
  ASSERT_FALSE(path.empty());
  facyl::CylinderClassifier c;
  ASSERT_NO_THROW(c.load(path));
  EXPECT_TRUE(c.loaded());
  EXPECT_TRUE(c.getModelInfo().has_fusion);
}

TEST(CylinderClassifier, ShippedModelSeparatesSimulatedObjectsItNeverSaw)
{
  // Scenes 1000..1007 (training used 50000..): the recognizer's objects, labelled by the
  // ground truth; cylinders must rank above the rest.
  facyl::CylinderClassifier c;
  c.load(facyl::CylinderClassifier::defaultModelPath());
  std::vector<float> pos, neg;
  for (std::uint64_t seed = 1000; seed < 1008; ++seed) {
    facyl::TabletopSceneParameters p =
      seed % 2 ? facyl::clutteredSceneParameters() : facyl::TabletopSceneParameters{};
    p.seed = seed;
    const facyl::RenderedScene scene = facyl::simulateTabletopScene(p);
    Cloud::Ptr cloud(new Cloud(scene.cloud));
    facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> rec;
    rec.setInputCloud(cloud);
    std::vector<facyl::RecognizedObject> objects;
    ASSERT_TRUE(rec.recognize(objects));
    std::vector<facyl::ObjectView> views;
    std::vector<int> labels;
    for (const auto& o : objects) {
      std::map<int, std::size_t> votes;
      for (const auto i : o.cluster.indices.indices)
        ++votes[scene.object_id[static_cast<std::size_t>(i)]];
      const auto best = std::max_element(votes.begin(), votes.end(),
                                         [](auto a, auto b) { return a.second < b.second; });
      if (best->first < 2 || best->second * 2 < o.cluster.indices.indices.size())
        continue;
      const auto& so = scene.scene.objects[static_cast<std::size_t>(best->first - 2)];
      views.push_back(facyl::objectView(*cloud, o.cluster.indices.indices, facyl::PinholeCamera{}));
      labels.push_back(so.cls == facyl::SceneClass::Cylinder);
    }
    const std::vector<float> p_net = c.cylinderProbabilities(views);
    ASSERT_EQ(p_net.size(), views.size());
    for (std::size_t k = 0; k < p_net.size(); ++k) {
      ASSERT_TRUE(p_net[k] >= 0.f && p_net[k] <= 1.f);
      (labels[k] ? pos : neg).push_back(p_net[k]);
      // One view alone gives what the batch gave.
      if (k == 0) {
        EXPECT_NEAR(c.cylinderProbability(views[k]), p_net[k], 1e-5f);
      }
    }
  }
  ASSERT_GE(pos.size(), 10u);
  ASSERT_GE(neg.size(), 10u);
  std::size_t above = 0;
  for (const float a : pos)
    for (const float b : neg)
      above += a > b;
  const double auc = static_cast<double>(above) / static_cast<double>(pos.size() * neg.size());
  EXPECT_GT(auc, 0.9) << pos.size() << " cylinders, " << neg.size() << " others";
}

TEST(CylinderClassifier, BadModelsGiveErrorsThatNameTheFile)
{
  const std::string good = facyl::CylinderClassifier::defaultModelPath();
  ASSERT_FALSE(good.empty());
  const std::string cfg = readFile(good.substr(0, good.size() - 5) + ".cfg");
  const std::string onnx = readFile(good);
  facyl::CylinderClassifier c;
  const auto message = [&](const std::string& path) {
    try {
      c.load(path);
    }
    catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // Missing model (named as given, not by its description's name: issue 41), missing
  // description.
  EXPECT_NE(message("/nonexistent/net.onnx").find("/nonexistent/net.onnx: no such file"),
            std::string::npos);
  EXPECT_NE(message(writeFile("undescribed.onnx", onnx)).find("undescribed.cfg: no such file"),
            std::string::npos);
  writeFile("lonely.cfg", cfg);
  EXPECT_NE(message(std::filesystem::temp_directory_path() / "facyl_test_classifier_lonely.onnx")
              .find("lonely.onnx: no such file"),
            std::string::npos);
  // Truncated.
  writeFile("truncated.cfg", cfg);
  const std::string truncated = writeFile("truncated.onnx", onnx.substr(0, onnx.size() / 3));
  EXPECT_NE(message(truncated).find("cannot read it as an ONNX network"), std::string::npos);
  EXPECT_FALSE(c.loaded());
  // Not ONNX at all.
  writeFile("text.cfg", cfg);
  EXPECT_NE(message(writeFile("text.onnx", "hello")).find("cannot read it"), std::string::npos);
  // Wrong input shape (channels) and wrong output count.
  // (another channel set than the shipped model's, whichever that is)
  std::string rgb = cfg;
  const auto channels_at = rgb.find("channels ");
  ASSERT_NE(channels_at, std::string::npos);
  const auto channels_end = rgb.find('\n', channels_at);
  const bool shipped_rgb = rgb.substr(channels_at, channels_end - channels_at) == "channels rgb";
  rgb.replace(channels_at, channels_end - channels_at,
              shipped_rgb ? "channels depth" : "channels rgb");
  writeFile("rgb.cfg", rgb);
  EXPECT_NE(message(writeFile("rgb.onnx", onnx)).find("does not take the described input"),
            std::string::npos);
  std::string sigmoid = cfg;
  sigmoid.replace(sigmoid.find("output softmax"), 14, "output sigmoid");
  writeFile("sigmoid.cfg", sigmoid);
  EXPECT_NE(message(writeFile("sigmoid.onnx", onnx)).find("outputs per view"), std::string::npos);
  // A bad description.
  writeFile("badcfg.cfg", "channels depth\nsize 64\nfusion 1 2\n");
  EXPECT_NE(message(writeFile("badcfg.onnx", onnx)).find("badcfg.cfg: line 3 (fusion)"),
            std::string::npos);
  // Caffe: the description first, then both network files are named when missing or bad.
  const auto caffe_message = [&](const std::string& prototxt, const std::string& model,
                                 const std::string& description) {
    try {
      c.loadCaffe(prototxt, model, description);
    }
    catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string paper_cfg = writeFile("paper.cfg", "channels rgb\nsize 227\n");
  EXPECT_NE(
    caffe_message("/nonexistent/deploy.prototxt", "/nonexistent/squeezenet.caffemodel", paper_cfg)
      .find("/nonexistent/deploy.prototxt: no such file"),
    std::string::npos);
  EXPECT_NE(caffe_message("a", "b", "/nonexistent/paper.cfg").find("paper.cfg: no such file"),
            std::string::npos);
  const std::string prototxt = writeFile("deploy.prototxt", "this is not a prototxt {");
  const std::string weights = writeFile("weights.caffemodel", "garbage");
  EXPECT_NE(caffe_message(prototxt, weights, paper_cfg).find("cannot read them as a Caffe network"),
            std::string::npos);
  EXPECT_FALSE(c.loaded());
  // Unloaded: a clear logic error, not a crash.
  EXPECT_THROW(c.cylinderProbability(facyl::ObjectView{}), std::logic_error);
}

TEST(CylinderClassifier, ViewsWithoutAnImageGiveNaN)
{
  facyl::CylinderClassifier c;
  c.load(facyl::CylinderClassifier::defaultModelPath());
  std::vector<int> idx;
  const Cloud::Ptr cloud = cylinderPatch(idx);
  const std::vector<float> p = c.cylinderProbabilities(
    {facyl::ObjectView{}, facyl::objectView(*cloud, idx, facyl::PinholeCamera{})});
  ASSERT_EQ(p.size(), 2u);
  EXPECT_TRUE(std::isnan(p[0]));
  EXPECT_TRUE(p[1] >= 0.f && p[1] <= 1.f);
  EXPECT_TRUE(c.cylinderProbabilities({}).empty());
}

// ------------------------------------------------------------------- in the recognizer

TEST(CylinderClassifier, RecognizerReportsACalibratedProbabilityPerObject)
{
  Cloud::Ptr cloud(new Cloud);
  ASSERT_EQ(pcl::io::loadPCDFile(FACYL_SOURCE_DIR "/data/default_scene.pcd", *cloud), 0);
  auto c = std::make_shared<facyl::CylinderClassifier>();
  c->load(facyl::CylinderClassifier::defaultModelPath());
  facyl::TabletopCylinderRecognizer<pcl::PointXYZRGBA> with, without;
  with.setClassifier(c);
  with.setInputCloud(cloud);
  without.setInputCloud(cloud);
  std::vector<facyl::RecognizedObject> a, b;
  ASSERT_TRUE(with.recognize(a));
  ASSERT_TRUE(without.recognize(b));
  std::size_t cylinders = 0;
  const float reject = with.getParameters().reject_below;
  for (const auto& o : a) {
    const auto& e = o.evidence;
    ASSERT_TRUE(e.p_cylinder >= 0.f && e.p_cylinder <= 1.f);
    ASSERT_TRUE(e.p_network >= 0.f && e.p_network <= 1.f);
    if (o.is_cylinder) {
      EXPECT_GE(e.p_cylinder, with.getParameters().decision.min_probability);
      ++cylinders;
    }
    if (!e.fitted && e.p_network < reject) {
      EXPECT_EQ(e.p_cylinder, e.p_network); // rejected before fitting
    }
  }
  EXPECT_GE(cylinders, 3u);
  EXPECT_GT(with.getTiming().classification, 0.0);
  // Without a classifier: the evidence model's probability for each fitted object (NaN for
  // the others), and the same decision rule.
  for (const auto& o : b) {
    EXPECT_EQ(std::isnan(o.evidence.p_cylinder), !o.evidence.fitted);
    EXPECT_TRUE(std::isnan(o.evidence.p_network));
    if (o.evidence.fitted) {
      EXPECT_FLOAT_EQ(o.evidence.p_cylinder,
                      facyl::geometricProbability(o.evidence, without.getParameters().decision));
      EXPECT_EQ(o.is_cylinder, facyl::acceptCylinder(o.evidence, without.getParameters().decision));
    }
  }
}
