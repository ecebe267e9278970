/*
 * facyl: the options of CylinderTracker shared by the tools that track (facyl_detect --track,
 * facyl_track_eval) and the Python module's Tracker: one table (settings_table.h), with the
 * defaults of CylinderTrackerParameters and the ranges of its validate().
 */
#pragma once

#include <facyl/tools/settings_table.h>

#include <facyl/tracking/cylinder_tracker.h>

#include <string>

namespace facyl_cli {

/** The tracker's options. */
inline const SettingsTable<facyl::CylinderTrackerParameters>&
trackerOptions()
{
  using S = facyl::CylinderTrackerParameters;
  static const SettingsTable<S> table = [] {
    SettingsTable<S> t;
    t.column = 25;
    t.validate = [](const S& s, std::string*) {
      // Its message lists every problem, each ended by "; ".
      std::string why = facyl::validate(s);
      while (!why.empty() && (why.back() == ' ' || why.back() == ';'))
        why.pop_back();
      return why;
    };
    t.options.push_back(integerOption<S>(
      "track-confirm-hits", "N", [](auto& s) -> auto& { return s.confirm_hits; },
      "frames a new track must be seen in to be confirmed (default {})"));
    t.options.push_back(integerOption<S>(
      "track-max-misses", "N", [](auto& s) -> auto& { return s.max_misses; },
      "missed frames a confirmed track survives (default {})"));
    t.options.push_back(integerOption<S>(
      "track-support-switch-frames", "N", [](auto& s) -> auto& { return s.support_switch_frames; },
      "frames in a row another support must win before it replaces the tracks' table "
      "(default {})"));
    return t;
  }();
  return table;
}

} // namespace facyl_cli
