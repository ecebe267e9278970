/*
 * facyl: fast cylinder detection for PCL.
 * The one random source of the simulators.
 */
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace facyl {

/** \brief Seeded random numbers that are identical on every standard library.
 *
 * std::mt19937_64's output is fixed by the C++ standard, but the std distributions
 * (uniform_real_distribution, normal_distribution, ...) are not: libstdc++, libc++ and MSVC
 * give different numbers for the same engine. The conversions here are our own (53-bit
 * uniform doubles, Box-Muller normals), so a seed names the same scene everywhere.
 * Not thread safe: one object per thread. */
class Random {
public:
  explicit Random(std::uint64_t seed)
      : engine_(seed)
  {
  }

  /** \brief 64 random bits. */
  std::uint64_t bits()
  {
    return engine_();
  }
  /** \brief Uniform in [0, 1). */
  double unit()
  {
    return static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }
  /** \brief Uniform in [a, b). */
  float uniform(float a, float b)
  {
    return a + static_cast<float>(unit() * (static_cast<double>(b) - a));
  }
  /** \brief Uniform integer in [lo, hi] (hi >= lo; the bias of the modulo is below 2^-40 for
   * the small ranges used here). */
  int integer(int lo, int hi)
  {
    const auto span = static_cast<std::uint64_t>(static_cast<std::int64_t>(hi) - lo + 1);
    return lo + static_cast<int>(engine_() % span);
  }
  /** \brief True with probability \a p. */
  bool chance(double p)
  {
    return unit() < p;
  }
  /** \brief Standard normal deviate (Box-Muller; the second value of each pair is kept). */
  float normal()
  {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = (static_cast<double>(engine_() >> 11) + 1.0) * 0x1.0p-53; // (0, 1]
    const double u2 = unit();
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double t = 2.0 * 3.14159265358979323846 * u2;
    spare_ = static_cast<float>(r * std::sin(t));
    has_spare_ = true;
    return static_cast<float>(r * std::cos(t));
  }

private:
  std::mt19937_64 engine_;
  float spare_{0.f};
  bool has_spare_{false};
};

} // namespace facyl
