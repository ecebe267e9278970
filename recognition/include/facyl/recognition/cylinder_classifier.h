/*
 * facyl: fast cylinder detection for PCL.
 * The shape classifier of the paper (III-B): a small CNN, run by OpenCV DNN, that tells
 * cylinders from the rest on each object's view, and a calibrated fusion of its output with
 * the fit's evidence.
 */
#pragma once

#include <facyl/recognition/classifier_input.h>
#include <facyl/recognition/cylinder_evidence.h>
#include <facyl/recognition/shape_classifier.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace facyl {

/** \brief Everything about a network that is not its weights: how views become its input,
 * how its output becomes a probability, and the fusion model. Read from a text file of
 * "key value..." lines (# starts a comment):
 * \code
 * channels depth          # rgb | depth | depthrgb (see ClassifierChannels)
 * size 64                 # input is channels x size x size
 * mean 127.5              # input value = (byte - mean) * scale
 * scale 0.0078431373
 * output softmax          # softmax: 2 outputs, the second is "cylinder"; sigmoid: 1 logit
 * fusion w0 w1 ... w19    # the evidence model's weights with this network: see
 *                         # evidenceProbability (kEvidenceFeatures numbers; or the
 *                         # kSideOnlyEvidenceFeatures of a model fitted before lid fits,
 *                         # which then has no say on them: has_lid_fusion false)
 * \endcode */
struct ClassifierModelInfo {
  ClassifierInputSpec input;
  float mean{127.5f};
  float scale{1.f / 127.5f};
  bool softmax{true};
  bool has_fusion{false};
  bool has_lid_fusion{false}; ///< the fusion weighs lid fits' features (CylinderEvidence::from_lid)
  std::array<float, kEvidenceFeatures> fusion{};
};

/** \brief Parses \a text (the file's contents) into \a info. \return an empty string, or what
 * is wrong (naming the line). */
std::string parseClassifierModelInfo(const std::string& text, ClassifierModelInfo& info);

/** \brief The CNN shape classifier (implements ShapeClassifier), run by OpenCV's DNN module.
 *
 * \code
 * auto classifier = std::make_shared<facyl::CylinderClassifier>();
 * classifier->load(facyl::CylinderClassifier::defaultModelPath()); // throws on error
 * recognizer.setClassifier(classifier);
 * \endcode
 * Models: ONNX (load: "net.onnx" with "net.cfg" beside it, see ClassifierModelInfo) or Caffe
 * (loadCaffe: prototxt + caffemodel + cfg), e.g. the paper's SqueezeNet with
 * "channels rgb", "size 227". All views given to cylinderProbabilities run as one batch.
 * Not thread-safe: one object per thread (the network holds its buffers).
 */
class CylinderClassifier : public ShapeClassifier {
public:
  using Ptr = std::shared_ptr<CylinderClassifier>;
  using ConstPtr = std::shared_ptr<const CylinderClassifier>;

  CylinderClassifier();
  ~CylinderClassifier() override;
  CylinderClassifier(const CylinderClassifier&) = delete;
  CylinderClassifier& operator=(const CylinderClassifier&) = delete;

  /** \brief Loads an ONNX network \a onnx_path and its description (the same path with the
   * extension .cfg). Checks both: the file exists and parses, the network takes the described
   * input and gives 1 (sigmoid) or 2 (softmax) outputs per view.
   * \throws std::runtime_error naming the file and what is wrong; the classifier is then
   * unloaded. */
  void load(const std::string& onnx_path);
  /** \brief Loads a Caffe network (\a prototxt, \a caffemodel) described by \a cfg_path.
   * \throws std::runtime_error as load. */
  void loadCaffe(const std::string& prototxt, const std::string& caffemodel,
                 const std::string& cfg_path);
  /** \brief True after a successful load. */
  bool loaded() const;
  const ClassifierModelInfo& getModelInfo() const
  {
    return info_;
  }
  /** \brief The model shipped with facyl (installed with the headers' share directory, or the
   * source tree's recognition/models when run from the build tree); empty if not found. */
  static std::string defaultModelPath();

  /** \brief NaN when the view gives no input image (no box, crop or pixels).
   * \throws std::logic_error when no model is loaded. */
  float cylinderProbability(const ObjectView& view) override;
  /** \brief One batch for all views; NaN for those without an input image. */
  std::vector<float> cylinderProbabilities(const std::vector<ObjectView>& views) override;
  /** \brief evidenceProbability with the model's fusion weights; \a p_network when the model
   * has none; the evidence model without a network (geometricProbability) when \a p_network
   * is NaN, or for a lid fit when the fusion has no lid features (has_lid_fusion). */
  float fuse(float p_network, const CylinderEvidence& evidence,
             const CylinderDecision& decision) const override;
  /** \brief Network outputs for ready-made input images (channels x size x size bytes each,
   * see classifierImage); for tests and training checks. */
  std::vector<float> probabilitiesOfImages(const std::vector<std::vector<std::uint8_t>>& images);
  std::string name() const override;
  /** \brief Whether the loaded model reads colour (channels rgb or depthrgb); true before a
   * load. */
  bool usesCrop() const override
  {
    return !loaded() || info_.input.channels != ClassifierChannels::Depth;
  }

private:
  struct Network;
  void check(const std::string& what);
  std::unique_ptr<Network> net_;
  ClassifierModelInfo info_;
  std::string name_;
};

} // namespace facyl
