/*
 * facyl: fast cylinder detection for PCL.
 */
#include <facyl/sample_consensus_alt/orientation_accumulator.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

namespace facyl {

bool
parseOrientationPrior(const std::string& name, OrientationPrior& prior)
{
  for (const auto p : {OrientationPrior::Uniform, OrientationPrior::Vertical,
                       OrientationPrior::VerticalStrong, OrientationPrior::Horizontal})
    if (name == toString(p)) {
      prior = p;
      return true;
    }
  return false;
}

std::string
toString(OrientationPrior prior)
{
  switch (prior) {
  case OrientationPrior::Uniform:
    return "uniform";
  case OrientationPrior::Vertical:
    return "vertical";
  case OrientationPrior::VerticalStrong:
    return "vertical-strong";
  case OrientationPrior::Horizontal:
    return "horizontal";
  }
  return "unknown";
}

GaussianMixture
GaussianMixture::fromPrior(OrientationPrior prior)
{
  GaussianComponent c;
  switch (prior) {
  case OrientationPrior::Uniform:
    break;
  case OrientationPrior::Vertical:
    c.mean = Eigen::Vector3f::UnitZ();
    break;
  case OrientationPrior::VerticalStrong:
    c.mean = Eigen::Vector3f::UnitZ();
    c.covariance = Eigen::Matrix3f::Identity() * 0.05f;
    break;
  case OrientationPrior::Horizontal:
    c.covariance = Eigen::Vector3f(0.5f, 0.5f, 0.02f).asDiagonal();
    break;
  }
  return GaussianMixture{{c}};
}

bool
GaussianMixture::isValid(std::string* why) const
{
  const auto fail = [why](const std::string& msg) {
    if (why)
      *why = msg;
    return false;
  };
  if (components.empty())
    return fail("the mixture has no component");
  for (std::size_t m = 0; m < components.size(); ++m) {
    const auto& c = components[m];
    std::ostringstream id;
    id << "component " << m << ": ";
    if (!(c.weight > 0.f) || !std::isfinite(c.weight))
      return fail(id.str() + "weight must be positive and finite");
    if (!c.mean.allFinite() || !c.covariance.allFinite())
      return fail(id.str() + "mean and covariance must be finite");
    if (!c.covariance.isApprox(c.covariance.transpose(), 1e-5f))
      return fail(id.str() + "covariance is not symmetric");
    Eigen::LLT<Eigen::Matrix3f> llt(c.covariance);
    if (llt.info() != Eigen::Success)
      return fail(id.str() + "covariance is not positive definite");
  }
  return true;
}

Eigen::Vector3f
foldToHemisphere(const Eigen::Vector3f& d)
{
  const bool flip = d.z() < 0.f || (d.z() == 0.f && (d.y() < 0.f || (d.y() == 0.f && d.x() < 0.f)));
  return flip ? Eigen::Vector3f(-d) : d;
}

namespace {
/** Standard normal deviates from mt19937_64 bits, identical on every platform. */
class NormalSource {
public:
  explicit NormalSource(std::uint64_t seed)
      : engine_(seed)
  {
  }
  double operator()()
  {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    // Box-Muller on two uniforms in (0, 1].
    const double u1 = (static_cast<double>(engine_() >> 11) + 1.0) * 0x1.0p-53;
    const double u2 = static_cast<double>(engine_() >> 11) * 0x1.0p-53;
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double t = 2.0 * M_PI * u2;
    spare_ = r * std::sin(t);
    has_spare_ = true;
    return r * std::cos(t);
  }
  double uniform()
  {
    return static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }

private:
  std::mt19937_64 engine_;
  double spare_{0.0};
  bool has_spare_{false};
};
} // namespace

Eigen::Matrix3Xf
sampleOrientations(const GaussianMixture& mixture, std::size_t count, std::uint64_t seed,
                   const Eigen::Matrix3f& frame)
{
  std::string why;
  if (!mixture.isValid(&why))
    throw std::invalid_argument("facyl::sampleOrientations: " + why);
  if (!frame.allFinite())
    throw std::invalid_argument("facyl::sampleOrientations: frame is not finite");
  std::vector<double> cumulative;
  std::vector<Eigen::Matrix3f> factors;
  double total = 0.0;
  for (const auto& c : mixture.components) {
    total += c.weight;
    cumulative.push_back(total);
    factors.push_back(Eigen::LLT<Eigen::Matrix3f>(c.covariance).matrixL());
  }
  NormalSource rng(seed);
  Eigen::Matrix3Xf out(3, static_cast<Eigen::Index>(count));
  for (std::size_t i = 0; i < count; ++i) {
    Eigen::Vector3f v;
    do {
      std::size_t m = 0;
      if (cumulative.size() > 1) {
        const double u = rng.uniform() * total;
        m = static_cast<std::size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), u) -
                                     cumulative.begin());
        m = std::min(m, cumulative.size() - 1);
      }
      const Eigen::Vector3f z(static_cast<float>(rng()), static_cast<float>(rng()),
                              static_cast<float>(rng()));
      v = mixture.components[m].mean + factors[m] * z;
    } while (!(v.norm() > 1e-6f)); // a zero draw has no direction: draw again
    out.col(static_cast<Eigen::Index>(i)) = foldToHemisphere((frame * v).normalized());
  }
  return out;
}

float
medianCellSpacing(const Eigen::Matrix3Xf& d)
{
  const Eigen::Index n = d.cols();
  if (n < 2)
    return static_cast<float>(M_PI / 2);
  std::vector<float> nearest(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::VectorXf dots = (d.transpose() * d.col(i)).cwiseAbs();
    float best = -1.f;
    for (Eigen::Index j = 0; j < n; ++j)
      if (j != i)
        best = std::max(best, dots(j));
    nearest[static_cast<std::size_t>(i)] = std::acos(std::min(1.f, best));
  }
  std::nth_element(nearest.begin(), nearest.begin() + n / 2, nearest.end());
  return nearest[static_cast<std::size_t>(n / 2)];
}

OrientationAccumulator::OrientationAccumulator(const Eigen::Matrix3Xf& directions)
    : directions_(directions)
{
  for (Eigen::Index i = 0; i < directions_.cols(); ++i) {
    const float len = directions_.col(i).norm();
    if (!(len > 0.f) || !std::isfinite(len))
      throw std::invalid_argument(
        "facyl::OrientationAccumulator: a direction is zero or not finite");
    directions_.col(i) = foldToHemisphere(directions_.col(i) / len);
  }
}

OrientationAccumulator
OrientationAccumulator::sample(const GaussianMixture& mixture, std::size_t count,
                               std::uint64_t seed, const Eigen::Matrix3f& frame)
{
  return OrientationAccumulator(sampleOrientations(mixture, count, seed, frame));
}

} // namespace facyl
