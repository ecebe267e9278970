/*
 * facyl: fast cylinder detection for PCL.
 * Private to the simulation module: what generateTabletopScene adds to a scene for
 * realism (TabletopSceneParameters: any camera roll, curved table, materials, far
 * background, robots). Each step changes nothing when its settings are off.
 */
#pragma once

#include <facyl/simulation/random.h>
#include <facyl/simulation/tabletop_scene.h>

namespace facyl {
namespace detail {

/** \brief All the steps below, in this order, on their own random numbers (\a
 * params.seed): the scene's other content stays what it is without them. */
void addRealism(const TabletopSceneParameters& params, TabletopScene& scene);

/** \brief Rolls the camera uniformly about its optical axis in any_roll_share of the
 * scenes. */
void rollAnyWay(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene);

/** \brief Curves the table top by a sag drawn from table_sag; the objects follow it. */
void curveTable(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene);

/** \brief Draws the materials of the table top, the floor and the objects; dark
 * surfaces are darkened in colour too. */
void drawMaterials(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene);

/** \brief A material drawn with \a shares: glossy, dark and transparent independently. */
SurfaceMaterial drawMaterial(Random& rng, const MaterialShares& shares);

/** \brief Far background items on the floor, in the camera's view, clear of the table,
 * the wall and each other (scenery). */
void addBackground(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene);

/** \brief A robot arm reaching from outside the image to above the objects (scenery). */
void addRobot(const TabletopSceneParameters& params, Random& rng, TabletopScene& scene);

} // namespace detail
} // namespace facyl
