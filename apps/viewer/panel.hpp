// The Dear ImGui panel: the chapter list, the live cost of each phase, the solver's
// iterations, the frame rate, and the controls of the scene, the material and the clock.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "apps/viewer/session.hpp"

namespace fem::viewer {

enum class StepMode {
  OneStepPerFrame,  // one step of dt per drawn frame, as fast as the stepper goes
  FixedDt,          // keeps up with the wall clock: as many steps of dt as it takes
};

// What the user can change from the panel, kept between frames.
struct PanelState {
  bool paused = false;
  bool step_once = false;
  bool reset = false;
  StepMode mode = StepMode::OneStepPerFrame;
  SessionSettings edited;              // the material and clock being edited
  std::optional<std::string> chapter;  // set when the user picks another chapter
  bool apply = false;                  // set when the user applies `edited`
  std::vector<std::string> meshes;     // the .msh files offered
  int mesh_index = 0;
  std::optional<std::string> mesh;  // set when the user picks another mesh
  std::string error;                // the last error, shown in red until the next change
  int behind_steps = 0;             // FixedDt: steps that did not fit in the last frame
};

constexpr float kPanelWidth = 340.0f;  // [pixels]

// Draws the panel for this frame and records the user's requests in `state`.
void draw_panel(const Session& session, double frames_per_second, PanelState& state);

}  // namespace fem::viewer
