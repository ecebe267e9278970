/*
 * facyl: tests of the randomized orientation accumulator (paper III-C1, eq. 1-2).
 */
#include <facyl/sample_consensus_alt/orientation_accumulator.h>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

using facyl::GaussianMixture;
using facyl::OrientationPrior;

namespace {
/** Mean of f(d) over directions. */
template <typename F>
double
meanOf(const Eigen::Matrix3Xf& d, F f)
{
  double s = 0.0;
  for (Eigen::Index i = 0; i < d.cols(); ++i)
    s += f(Eigen::Vector3f(d.col(i)));
  return s / static_cast<double>(d.cols());
}

/** The same statistic by an independent Monte Carlo of the mixture (std::normal_distribution,
 * another generator), folded the same way. */
template <typename F>
double
referenceMean(const GaussianMixture& g, F f, int n = 200000)
{
  std::mt19937 rng(12345);
  std::normal_distribution<double> z;
  std::vector<double> weights;
  for (const auto& c : g.components)
    weights.push_back(c.weight);
  std::discrete_distribution<int> pick(weights.begin(), weights.end());
  double s = 0.0;
  for (int i = 0; i < n; ++i) {
    const auto& c = g.components[static_cast<std::size_t>(pick(rng))];
    const Eigen::Matrix3d l = Eigen::LLT<Eigen::Matrix3d>(c.covariance.cast<double>()).matrixL();
    const Eigen::Vector3d v = c.mean.cast<double>() + l * Eigen::Vector3d(z(rng), z(rng), z(rng));
    s += f(facyl::foldToHemisphere(v.normalized().cast<float>()));
  }
  return s / n;
}
} // namespace

TEST(OrientationAccumulator, SameSeedSameSamples)
{
  const auto g = GaussianMixture::fromPrior(OrientationPrior::Vertical);
  const auto a = facyl::sampleOrientations(g, 450, 7);
  const auto b = facyl::sampleOrientations(g, 450, 7);
  const auto c = facyl::sampleOrientations(g, 450, 8);
  EXPECT_TRUE(a.isApprox(b, 0.f));
  EXPECT_FALSE(a.isApprox(c, 1e-3f));
}

TEST(OrientationAccumulator, SamplesAreUnitAndFolded)
{
  const auto d =
    facyl::sampleOrientations(GaussianMixture::fromPrior(OrientationPrior::Uniform), 1000, 1);
  for (Eigen::Index i = 0; i < d.cols(); ++i) {
    EXPECT_NEAR(d.col(i).norm(), 1.f, 1e-5f);
    EXPECT_GE(d(2, i), 0.f);
  }
}

TEST(OrientationAccumulator, UniformPriorIsUniformOnTheSphere)
{
  const int n = 20000;
  const auto d =
    facyl::sampleOrientations(GaussianMixture::fromPrior(OrientationPrior::Uniform), n, 3);
  // On the uniform sphere, |z| is uniform on [0, 1]: mean 1/2, variance 1/12; and the
  // mean direction of the folded samples has no x, y part.
  const double tol = 4.0 * std::sqrt(1.0 / 12.0 / n);
  EXPECT_NEAR(meanOf(d, [](const Eigen::Vector3f& v) { return v.z(); }), 0.5, tol);
  EXPECT_NEAR(meanOf(d, [](const Eigen::Vector3f& v) { return v.z() * v.z(); }), 1.0 / 3.0, tol);
  EXPECT_NEAR(meanOf(d, [](const Eigen::Vector3f& v) { return v.x(); }), 0.0, 2 * tol);
  EXPECT_NEAR(meanOf(d, [](const Eigen::Vector3f& v) { return v.y(); }), 0.0, 2 * tol);
}

TEST(OrientationAccumulator, MeanAndSpreadMatchTheMixture)
{
  GaussianMixture two;
  two.components.push_back({0.7f, Eigen::Vector3f(0, 0, 1), Eigen::Matrix3f::Identity() * 0.05f});
  two.components.push_back({0.3f, Eigen::Vector3f(1, 0, 0), Eigen::Matrix3f::Identity() * 0.02f});
  for (const auto& g : {GaussianMixture::fromPrior(OrientationPrior::Vertical),
                        GaussianMixture::fromPrior(OrientationPrior::VerticalStrong),
                        GaussianMixture::fromPrior(OrientationPrior::Horizontal), two}) {
    const int n = 20000;
    const auto d = facyl::sampleOrientations(g, n, 11);
    const auto z = [](const Eigen::Vector3f& v) { return double(v.z()); };
    const auto zz = [](const Eigen::Vector3f& v) { return double(v.z() * v.z()); };
    const auto xx = [](const Eigen::Vector3f& v) { return double(v.x() * v.x()); };
    // Each statistic is a mean of values in [0, 1]: its standard error is at most 0.5/sqrt(n).
    const double tol = 4.0 * 0.5 / std::sqrt(double(n));
    EXPECT_NEAR(meanOf(d, z), referenceMean(g, z), tol);
    EXPECT_NEAR(meanOf(d, zz), referenceMean(g, zz), tol);
    EXPECT_NEAR(meanOf(d, xx), referenceMean(g, xx), tol);
  }
}

TEST(OrientationAccumulator, PriorsConcentrateWhereTheySay)
{
  const int n = 5000;
  const auto strong =
    facyl::sampleOrientations(GaussianMixture::fromPrior(OrientationPrior::VerticalStrong), n, 5);
  const auto mild =
    facyl::sampleOrientations(GaussianMixture::fromPrior(OrientationPrior::Vertical), n, 5);
  const auto flat =
    facyl::sampleOrientations(GaussianMixture::fromPrior(OrientationPrior::Horizontal), n, 5);
  const auto near_up = [](const Eigen::Matrix3Xf& d) {
    return (d.row(2).array() > std::cos(20.0 * M_PI / 180.0)).cast<double>().mean();
  };
  EXPECT_GT(near_up(strong), near_up(mild));
  EXPECT_GT(near_up(mild), 1.0 - std::cos(20.0 * M_PI / 180.0)); // more than uniform
  EXPECT_LT(near_up(flat), 0.01);
}

TEST(OrientationAccumulator, FrameRotatesThePrior)
{
  Eigen::Matrix3f frame;
  frame << Eigen::Vector3f::UnitY(), Eigen::Vector3f::UnitZ(), Eigen::Vector3f::UnitX();
  const auto d = facyl::sampleOrientations(
    GaussianMixture::fromPrior(OrientationPrior::VerticalStrong), 2000, 9, frame);
  // "up" is now x: the samples gather around +-x.
  EXPECT_GT(d.row(0).array().abs().mean(), 0.9f);
}

TEST(OrientationAccumulator, InvalidMixturesAreRejected)
{
  GaussianMixture empty;
  std::string why;
  EXPECT_FALSE(empty.isValid(&why));
  EXPECT_FALSE(why.empty());
  EXPECT_THROW(facyl::sampleOrientations(empty, 10, 0), std::invalid_argument);
  GaussianMixture bad = GaussianMixture::fromPrior(OrientationPrior::Uniform);
  bad.components[0].covariance(0, 0) = -1.f;
  EXPECT_FALSE(bad.isValid());
  bad = GaussianMixture::fromPrior(OrientationPrior::Uniform);
  bad.components[0].weight = 0.f;
  EXPECT_FALSE(bad.isValid());
  EXPECT_THROW(facyl::OrientationAccumulator(Eigen::Matrix3Xf::Zero(3, 2)), std::invalid_argument);
}

TEST(OrientationAccumulator, CellSizeMatchesThePaper)
{
  const auto acc = facyl::OrientationAccumulator::sample(
    GaussianMixture::fromPrior(OrientationPrior::Uniform), 450, 0);
  EXPECT_EQ(acc.size(), 450u);
  EXPECT_NEAR(acc.cellRadius() * 180.f / M_PI, 3.82f, 0.01f);
  // Random cells are closer than a lattice to their nearest neighbour half the time.
  const float spacing = facyl::medianCellSpacing(acc.directions()) * 180.f / M_PI;
  EXPECT_GT(spacing, 2.f);
  EXPECT_LT(spacing, 8.f);
}

TEST(OrientationAccumulator, PresetNamesRoundTrip)
{
  for (const auto p : {OrientationPrior::Uniform, OrientationPrior::Vertical,
                       OrientationPrior::VerticalStrong, OrientationPrior::Horizontal}) {
    OrientationPrior q;
    ASSERT_TRUE(facyl::parseOrientationPrior(facyl::toString(p), q));
    EXPECT_EQ(p, q);
  }
  OrientationPrior q;
  EXPECT_FALSE(facyl::parseOrientationPrior("diagonal", q));
}
