#include "apps/viewer/panel.hpp"

#include <imgui.h>

#include <algorithm>
#include <filesystem>

#include "apps/viewer/markers.hpp"
#include "chapters/registry.hpp"

namespace fem::viewer {

namespace {

void chapter_list(const Session& session, PanelState& state) {
  ImGui::TextUnformatted("Chapter (the state carries over)");
  for (const ChapterInfo& chapter : chapters()) {
    if (ImGui::RadioButton(chapter.id.c_str(), session.chapter() == chapter.id))
      state.chapter = chapter.id;
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", chapter.title.c_str());
  }
}

// One bar per phase, as a fraction of the whole step: what each chapter buys shows as
// bars that shrink (and the step time beside them).
void phase_bars(const Session& session) {
  const StepProfile mean = session.mean_profile();
  const double step_ms = 1e3 * mean.step.seconds;
  ImGui::Text("Step %.2f ms (mean of the last %zu steps)", step_ms, session.history().size());
  for (const StepProfile::Phase& phase : StepProfile::phases()) {
    if (phase.cost == &StepProfile::step) continue;  // the whole, drawn as the step time
    const char* name = phase.name;
    const double seconds = (mean.*phase.cost).seconds;
    char label[32];
    std::snprintf(label, sizeof label, "%.3f ms", 1e3 * seconds);
    const float fraction =
        mean.step.seconds > 0 ? static_cast<float>(seconds / mean.step.seconds) : 0;
    ImGui::ProgressBar(fraction, ImVec2(180, 0), label);
    ImGui::SameLine();
    ImGui::TextUnformatted(name);
  }
  float history[64];
  int count = 0;
  float highest = 0.0f;
  for (const StepProfile& p : session.history()) {
    if (count == 64) break;
    history[count] = static_cast<float>(1e3 * p.step.seconds);
    highest = std::max(highest, history[count++]);
  }
  // The graph's scale: 0 at the bottom, `top` at the top.
  const float top = 1.2f * highest + 1e-3f;
  ImGui::Text("step time of the last %d steps (0 to %.2f ms)", count, top);
  ImGui::PlotLines("##step time", history, count, 0, nullptr, 0.0f, top,
                   ImVec2(kPanelWidth - 20, 40));
  ImGui::Text("CG: %d iterations, residual %.1e", session.last_profile().cg_iterations,
              session.last_profile().relative_residual);
  if (!session.last_profile().converged)
    ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "the solve stopped at the iteration cap");
}

void clock_controls(PanelState& state) {
  ImGui::Checkbox("pause (space)", &state.paused);
  ImGui::SameLine();
  if (ImGui::Button("step (s)")) state.step_once = true;
  ImGui::SameLine();
  if (ImGui::Button("reset (r)")) state.reset = true;
  int mode = state.mode == StepMode::OneStepPerFrame ? 0 : 1;
  ImGui::RadioButton("one step per frame", &mode, 0);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("one step of dt per drawn frame, as fast as the stepper goes");
  ImGui::RadioButton("keep up with the wall clock", &mode, 1);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("as many steps of dt per frame as the wall clock asks (at most 8)");
  state.mode = mode == 0 ? StepMode::OneStepPerFrame : StepMode::FixedDt;
  if (state.mode == StepMode::FixedDt && state.behind_steps > 0)
    ImGui::TextColored(ImVec4(1, 0.7f, 0.2f, 1), "behind the wall clock: the steps are too slow");
}

// What the coloured points on the body are, in the renderer's colours.
void legend(const Scene& scene) {
  const auto entry = [](const Marker& m) {
    ImGui::ColorButton(m.meaning, ImVec4(m.rgb[0], m.rgb[1], m.rgb[2], 1.0f),
                       ImGuiColorEditFlags_NoTooltip, ImVec2(10, 10));
    ImGui::SameLine();
    ImGui::TextUnformatted(m.meaning);
  };
  bool shown[3] = {};  // by Kind: the scene's kinds only (the cantilever has fixed nodes)
  for (const NodeConstraint& c : scene.constraints) shown[static_cast<std::size_t>(c.kind)] = true;
  for (const auto kind :
       {NodeConstraint::Kind::Fixed, NodeConstraint::Kind::Line, NodeConstraint::Kind::Plane})
    if (shown[static_cast<std::size_t>(kind)]) entry(constraint_marker(kind));
  entry(kSpringMarker);
}

bool slider(const char* label, double& value, double lo, double hi, bool logarithmic) {
  float v = static_cast<float>(value);
  const bool changed = ImGui::SliderFloat(label, &v, static_cast<float>(lo), static_cast<float>(hi),
                                          logarithmic ? "%.3g" : "%.3f",
                                          logarithmic ? ImGuiSliderFlags_Logarithmic : 0);
  if (changed) value = v;
  return changed;
}

void scene_controls(const Session& session, PanelState& state) {
  SessionSettings& s = state.edited;
  int scene = s.scene == "sliding" ? 1 : 0;
  const char* scenes[] = {"cantilever", "sliding"};
  if (ImGui::Combo("scene", &scene, scenes, 2)) s.scene = scenes[scene];
  if (!state.meshes.empty()) {
    std::vector<const char*> names;
    for (const std::string& m : state.meshes) names.push_back(m.c_str());
    if (ImGui::Combo("mesh", &state.mesh_index, names.data(), static_cast<int>(names.size())))
      state.mesh = state.meshes[state.mesh_index];
  }
  slider("E [Pa]", s.material.youngs_modulus, 1e3, 1e8, true);
  slider("nu", s.material.poisson_ratio, 0.0, 0.49, false);
  slider("alpha [1/s]", s.damping.alpha, 0.0, 10.0, false);
  slider("beta [s]", s.damping.beta, 0.0, 0.1, false);
  slider("dt [s]", s.dt, 1e-4, 0.05, true);
  slider("spring", s.spring, 0.1, 100.0, true);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("stiffness of the mouse spring, in body weights per bounding-box diagonal");
  if (ImGui::Button("apply")) state.apply = true;
  ImGui::SameLine();
  ImGui::TextDisabled("(a new scene restarts from rest)");
  ImGui::Text("%s: %d nodes, %d tets",
              std::filesystem::path(session.scene().mesh.file).filename().c_str(),
              session.scene().mesh.num_nodes(), session.scene().mesh.num_tets());
}

}  // namespace

void draw_panel(const Session& session, double frames_per_second, PanelState& state) {
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(kPanelWidth, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("Eigen FEM tutorial");
  ImGui::Text("%.1f frames/s   t = %.2f s   %lld steps", frames_per_second, session.time(),
              session.steps());
  chapter_list(session, state);
  // Chapters before 09 use one thread whatever the count (--threads or OMP_NUM_THREADS).
  // The last steps' teams as the stepper recorded them, not the option.
  ImGui::Text("threads: %d-%d %s", session.threads_ran().first, session.threads_ran().second,
              !session.uses_threads()      ? "(this chapter is single-threaded)"
              : session.settings().threads ? "(asked)"
                                           : "(the library's choice)");
  ImGui::Separator();
  phase_bars(session);
  ImGui::Separator();
  clock_controls(state);
  if (ImGui::CollapsingHeader("scene, material, clock")) scene_controls(session, state);
  ImGui::Separator();
  legend(session.scene());
  ImGui::TextDisabled("drag the body: pull it; drag elsewhere: orbit");
  ImGui::TextDisabled("right/middle drag: pan; wheel: zoom");
  const std::string& warning = state.error.empty() ? session.message() : state.error;
  if (!warning.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "%s", warning.c_str());
  ImGui::End();
}

}  // namespace fem::viewer
