/*
 * facyl: options of the simulated sensor's image shared by the tools that render scenes
 * (facyl_synth, facyl_tabletop_eval): resolution and random missing pixels.
 */
#pragma once

#include <facyl/tools/cli.h>

#include <facyl/simulation/tabletop_scene.h>

#include <cstdio>
#include <set>
#include <stdexcept>
#include <string>

namespace facyl_cli {

/** Options with a value that applySceneImageOptions reads. */
inline std::set<std::string>
sceneImageOptions()
{
  return {"--resolution", "--dropout"};
}

/** The help lines of those options. */
inline const char*
sceneImageOptionsHelp()
{
  return "  --resolution WxH   image size in pixels, 64..4096 each (default: the sensor's, "
         "640x480);\n"
         "                     the field of view is kept\n"
         "  --dropout P        share of pixels missing at random, in [0, 0.5] (default: the\n"
         "                     sensor's, 0.002; not with --sensor random)\n";
}

/** Reads --resolution and --dropout into \a p (the sensor preset already applied; a random
 * sensor scales the resolution's camera and refuses --dropout).
 * \throws std::invalid_argument for a malformed or out-of-range value. */
inline void
applySceneImageOptions(const Arguments& args, facyl::TabletopSceneParameters& p)
{
  if (args.has("--resolution")) {
    const std::string text = args.text("--resolution", "");
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' || w < 64 ||
        h < 64 || w > 4096 || h > 4096)
      throw std::invalid_argument("--resolution: expected WxH with 64 <= W, H <= 4096, got '" +
                                  text + "'");
    p.camera = facyl::resizedCamera(p.camera, w, h);
  }
  if (p.sensor.randomize && args.has("--dropout"))
    throw std::invalid_argument("--dropout cannot be combined with --sensor random (its "
                                "dropout is drawn per scene)");
  p.sensor.dropout = static_cast<float>(args.number("--dropout", p.sensor.dropout, 0.0, 0.5));
}

} // namespace facyl_cli
