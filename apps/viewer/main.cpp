// fem_viewer: the simulation in a window. Pull the body with the mouse, switch chapters
// while it moves, and watch the cost of each phase change.
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <stb/stb_image_write.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "apps/viewer/controls.hpp"
#include "apps/viewer/panel.hpp"
#include "apps/viewer/renderer.hpp"
#include "chapters/registry.hpp"
#include "common/atomic_file.hpp"
#include "common/build_info.hpp"
#include "common/cli.hpp"
#include "common/json.hpp"
#include "common/machine_record.hpp"
#include "common/threads.hpp"

namespace fv = fem::viewer;

namespace {

struct Options {
  std::string chapter;
  int frames = 0;  // 0: until the window is closed
  int width = 1280, height = 800;
  std::optional<fv::DragReplay> replay;
  std::string screenshot, report;
  bool fixed_dt = false;
  bool paused = false;
};

// Keys pressed since the last frame (space, s, r), collected by a GLFW callback that the
// ImGui backend chains to.
struct Keys {
  bool pause = false, step = false, reset = false;
};
Keys g_keys;
std::string g_glfw_error;

void on_key(GLFWwindow*, int key, int, int action, int) {
  if (action != GLFW_PRESS || ImGui::GetCurrentContext() == nullptr ||
      ImGui::GetIO().WantCaptureKeyboard)
    return;
  if (key == GLFW_KEY_SPACE) g_keys.pause = true;
  if (key == GLFW_KEY_S) g_keys.step = true;
  if (key == GLFW_KEY_R) g_keys.reset = true;
}

double g_wheel = 0.0;
void on_scroll(GLFWwindow*, double, double dy) {
  if (ImGui::GetCurrentContext() == nullptr || !ImGui::GetIO().WantCaptureMouse) g_wheel += dy;
}

std::vector<std::string> list_meshes(const std::string& current) {
  std::vector<std::string> meshes;
  for (const char* dir : {"meshes", "meshes/generated"}) {
    const std::filesystem::path path = std::filesystem::path(fem::source_dir()) / dir;
    if (!std::filesystem::is_directory(path)) continue;
    for (const auto& entry : std::filesystem::directory_iterator(path))
      if (entry.path().extension() == ".msh") meshes.push_back(entry.path().string());
  }
  std::sort(meshes.begin(), meshes.end());
  if (std::find(meshes.begin(), meshes.end(), current) == meshes.end()) meshes.push_back(current);
  return meshes;
}

void write_screenshot(const std::string& path, int width, int height) {
  std::vector<unsigned char> pixels(static_cast<std::size_t>(3) * width * height);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, pixels.data());
  stbi_flip_vertically_on_write(1);  // OpenGL's rows start at the bottom
  // Into memory, then written whole (common/atomic_file.hpp): stb's own file writer does not
  // say when the disk is full.
  std::string png;
  const auto append = [](void* to, void* data, int size) {
    static_cast<std::string*>(to)->append(static_cast<const char*>(data),
                                          static_cast<std::size_t>(size));
  };
  if (!stbi_write_png_to_func(append, &png, width, height, 3, pixels.data(), 3 * width))
    throw std::runtime_error("cannot encode the screenshot " + path);
  fem::write_file_atomically(path, png);
  std::cout << "fem_viewer: screenshot written to " << path << "\n";
}

std::string json_vector(const Eigen::Vector3d& v) {
  std::ostringstream out;
  out.precision(17);
  out << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return out.str();
}

// The facts of a scripted run, for the smoke test and for the closing numbers.
struct RunRecord {
  int frames = 0;
  int width = 0, height = 0;  // of the framebuffer
  bool paused = false;        // at the end of the run
  double seconds = 0.0;
  double step_seconds = 0.0;
  long long steps = 0;
  int grabbed_node = -1;
  Eigen::Vector3d node_at_grab = Eigen::Vector3d::Zero(), target = Eigen::Vector3d::Zero();
};

void write_report(std::ostream& out, const RunRecord& r, const fv::Session& session) {
  out.precision(17);
  // What the frame rate depends on: the renderer (a GPU or Mesa's software llvmpipe), the
  // CPU that steps and may also draw, and how the stepper was compiled.
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const fem::BuildInfo build = fem::build_info();
  out << "{\n  \"chapter\": " << fem::json_string(session.chapter())
      << ",\n  \"mesh\": " << fem::json_string(session.scene().mesh.file) << ",\n  \"nodes\": "
      << session.scene().mesh.num_nodes()
      // The stepper's own record of the steps (the most and the fewest threads a step ran
      // on: an adaptive team may take one), and the count asked for (0: none, the library's
      // choice).
      << ",\n  \"threads\": " << session.threads_ran().second
      << ",\n  \"threads_fewest\": " << session.threads_ran().first
      << ",\n  \"threads_asked\": " << session.settings().threads
      << ",\n  \"paused\": " << (r.paused ? "true" : "false") << ",\n  \"width\": " << r.width
      << ",\n  \"height\": " << r.height
      << ",\n  \"renderer\": " << fem::json_string(renderer ? renderer : "unknown")
      << ",\n  \"cpu\": " << fem::json_string(fem::cpu_model()) << ",\n  \"machine\": {"
      << fem::machine_record_json(fem::machine_record()) << "}"
      << ",\n  \"compiler\": " << fem::json_string(build.compiler)
      << ",\n  \"flags\": " << fem::json_string(build.flags) << ",\n  \"frames\": " << r.frames
      << ",\n  \"seconds\": " << r.seconds
      << ",\n  \"frames_per_second\": " << r.frames / std::max(r.seconds, 1e-9)
      << ",\n  \"steps\": " << r.steps
      << ",\n  \"mean_step_ms\": " << 1e3 * r.step_seconds / std::max<long long>(r.steps, 1)
      << ",\n  \"grabbed_node\": " << r.grabbed_node
      << ",\n  \"node_at_grab\": " << json_vector(r.node_at_grab)
      << ",\n  \"target\": " << json_vector(r.target) << ",\n  \"node_at_end\": "
      << json_vector(r.grabbed_node >= 0
                         ? Eigen::Vector3d(session.state().x.segment<3>(3 * r.grabbed_node))
                         : Eigen::Vector3d::Zero())
      << "\n}\n";
}

// Steps the session as the clock mode says; returns the seconds spent stepping.
double advance(fv::Session& session, fv::PanelState& panel, double frame_seconds) {
  const auto start = std::chrono::steady_clock::now();
  int steps = panel.paused ? 0 : 1;
  if (!panel.paused && panel.mode == fv::StepMode::FixedDt) {
    // As many steps as the wall clock asks for, at most 8 a frame: beyond that the
    // simulation falls behind and the panel says so.
    const int wanted = static_cast<int>(frame_seconds / session.scene().dt + 0.5);
    steps = std::min(wanted, 8);
    panel.behind_steps = std::max(wanted - steps, 0);
  }
  if (panel.step_once) steps = std::max(steps, 1);
  panel.step_once = false;
  for (int k = 0; k < steps; ++k)
    if (!session.step()) break;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Frames the mesh in the part of the window right of the panel: farther away by the
// ratio of the widths, and moved right by half the panel's width.
void frame_beside_panel(fv::OrbitCamera& camera, const fem::TetMesh& mesh) {
  camera.frame(Eigen::AlignedBox3d(mesh.X.rowwise().minCoeff(), mesh.X.rowwise().maxCoeff()));
  int width = 0, height = 0;
  glfwGetFramebufferSize(glfwGetCurrentContext(), &width, &height);
  if (width < 2 * fv::kPanelWidth) return;
  camera.distance *= width / (width - fv::kPanelWidth);
  camera.pan(0.5 * fv::kPanelWidth, 0.0, height);
}

// Applies what the user asked for in the panel or with the keys.
void handle_requests(std::unique_ptr<fv::Session>& session, fv::PanelState& panel,
                     fv::Renderer& renderer, fv::OrbitCamera& camera) {
  if (g_keys.pause) panel.paused = !panel.paused;
  if (g_keys.step) panel.step_once = true;
  if (g_keys.reset) panel.reset = true;
  g_keys = {};
  try {
    if (panel.chapter) session->set_chapter(*panel.chapter);
    if (panel.reset) session->reset();
    if (panel.apply) {
      const std::string old_scene = session->settings().scene;
      session->apply(panel.edited);
      if (session->settings().scene != old_scene) renderer.set_scene(session->scene());
      panel.error.clear();
    }
    if (panel.mesh) {
      fem::TetMesh mesh = fem::load_mesh(*panel.mesh);
      session = std::make_unique<fv::Session>(std::move(mesh), panel.edited, session->chapter());
      renderer.set_scene(session->scene());
      frame_beside_panel(camera, session->scene().mesh);
      panel.error.clear();
    }
  } catch (const std::exception& e) {
    panel.error = e.what();
  }
  panel.chapter.reset();
  panel.mesh.reset();
  panel.reset = panel.apply = false;
}

GLFWwindow* open_window(const Options& options) {
  glfwSetErrorCallback([](int, const char* text) { g_glfw_error = text; });
  if (!glfwInit())
    throw std::runtime_error(
        "cannot open a window: " + g_glfw_error +
        ". The viewer needs a display: run it on a desktop, or headless under Xvfb: "
        "xvfb-run -a build/release/fem_viewer");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 4);
  GLFWwindow* window = glfwCreateWindow(options.width, options.height,
                                        "Eigen FEM tutorial: fem_viewer", nullptr, nullptr);
  if (window == nullptr) {
    glfwTerminate();
    throw std::runtime_error("cannot create an OpenGL 3.3 core window: " + g_glfw_error);
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(options.frames > 0 ? 0 : 1);  // scripted runs measure, not wait for vsync
  glfwSetKeyCallback(window, on_key);
  glfwSetScrollCallback(window, on_scroll);
  return window;
}

// The window, its OpenGL context and Dear ImGui, released in reverse order on every path.
struct Window {
  explicit Window(const Options& options) : handle(open_window(options)) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left in the working directory
    ImGui_ImplGlfw_InitForOpenGL(handle, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
  }
  ~Window() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    glfwDestroyWindow(handle);
    glfwTerminate();
  }
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;
  GLFWwindow* handle;
};

fv::MouseInput mouse_from(GLFWwindow* window) {
  fv::MouseInput mouse;
  glfwGetCursorPos(window, &mouse.x, &mouse.y);
  mouse.left = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  mouse.right = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
  mouse.middle = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS;
  mouse.wheel = g_wheel;
  g_wheel = 0.0;
  return mouse;
}

fv::PanelState initial_panel(const fv::Session& session, const Options& options) {
  fv::PanelState panel;
  panel.edited = session.settings();
  panel.paused = options.paused;
  panel.mode = options.fixed_dt ? fv::StepMode::FixedDt : fv::StepMode::OneStepPerFrame;
  const std::string& mesh = session.scene().mesh.file;
  panel.meshes = list_meshes(mesh);
  panel.mesh_index = static_cast<int>(std::find(panel.meshes.begin(), panel.meshes.end(), mesh) -
                                      panel.meshes.begin());
  return panel;
}

// The dragged node where the grab began, and where the mouse pulls it now.
void record_grab(const fv::Session& session, bool had_grab, RunRecord& record) {
  if (!had_grab && session.grabbed()) {
    record.grabbed_node = session.grabbed()->node;
    record.node_at_grab = session.state().x.segment<3>(3 * record.grabbed_node);
  }
  if (session.grabbed()) record.target = session.grabbed()->target;
}

void report_run(const RunRecord& record, const fv::Session& session, const Options& options) {
  std::cout << "fem_viewer: " << record.frames << " frames in " << record.seconds << " s ("
            << record.frames / std::max(record.seconds, 1e-9) << " frames/s), chapter "
            << session.chapter() << ", mean step "
            << 1e3 * record.step_seconds / std::max<long long>(record.steps, 1)
            << " ms, threads the steps ran on: " << session.threads_ran().first << "-"
            << session.threads_ran().second << "\n";
  if (!options.report.empty()) {
    fem::write_file_atomically(options.report,
                               [&](std::ostream& out) { write_report(out, record, session); });
    std::cout << "fem_viewer: report written to " << options.report << "\n";
  }
}

void run(GLFWwindow* window, std::unique_ptr<fv::Session>& session, const Options& options) {
  fv::Renderer renderer;
  renderer.set_scene(session->scene());
  fv::OrbitCamera camera;
  frame_beside_panel(camera, session->scene().mesh);
  fv::MouseControls controls;
  fv::PanelState panel = initial_panel(*session, options);
  std::optional<fv::DragReplay> replay = options.replay;  // it remembers where it started
  RunRecord record;
  const auto start = std::chrono::steady_clock::now();
  auto last_frame = start;
  for (int frame = 0; !glfwWindowShouldClose(window); ++frame) {
    if (options.frames > 0 && frame >= options.frames) break;
    glfwPollEvents();
    int width = 0, height = 0;
    glfwGetFramebufferSize(window, &width, &height);
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();

    const fv::MouseInput mouse =
        replay ? replay->input(frame, width, height, camera, *session) : mouse_from(window);
    const bool had_grab = session->grabbed().has_value();
    controls.update(mouse, !replay && ImGui::GetIO().WantCaptureMouse, width, height, camera,
                    *session);
    record_grab(*session, had_grab, record);

    const auto now = std::chrono::steady_clock::now();
    const double frame_seconds = std::chrono::duration<double>(now - last_frame).count();
    last_frame = now;
    const long long steps_before = session->steps();
    record.step_seconds += advance(*session, panel, frame_seconds);
    record.steps += session->steps() - steps_before;

    draw_panel(*session, ImGui::GetIO().Framerate, panel);
    ImGui::Render();
    renderer.draw(session->state(), session->grabbed(), camera, width, height);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    handle_requests(session, panel, renderer, camera);
    if (!options.screenshot.empty() && options.frames > 0 && frame == options.frames - 1)
      write_screenshot(options.screenshot, width, height);
    glfwSwapBuffers(window);
    record.frames = frame + 1;
    record.width = width;
    record.height = height;
    record.paused = panel.paused;
  }
  record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report_run(record, *session, options);
}

void add_viewer_options(fem::ArgParser& args) {
  using fem::latest_chapter;
  add_scene_options(args, "meshes/plate_poster.msh");
  add_solver_options(args);
  add_thread_option(args);
  args.option("chapter", "NAME", "stepper to start with (switch in the panel)",
              latest_chapter().id);
  args.option("frames", "N", "stop after N frames (0: run until the window is closed)", "0");
  args.option("width", "PIXELS", "window width", "1280");
  args.option("height", "PIXELS", "window height", "800");
  args.option("replay-drag", "SPEC",
              "scripted mouse drag: 'auto' (pull the far end up) or x0,y0,x1,y1 in window "
              "fractions; needs --frames",
              "");
  args.option("screenshot", "FILE", "write a PNG of the last frame (needs --frames)", "");
  args.option("report", "FILE", "write the run's facts as JSON (frame rate, dragged node)", "");
  args.flag("fixed-dt", "start in fixed-dt mode (simulated time follows the wall clock)");
  args.flag("paused", "start paused (space resumes): --frames then measures drawing alone");
}

Options viewer_options(const fem::ArgParser& args) {
  using fem::UsageError;
  Options options;
  try {
    options.chapter = fem::find_chapter(args.get("chapter")).id;
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  options.frames = args.get_int("frames");
  options.width = args.get_int("width");
  options.height = args.get_int("height");
  options.screenshot = args.get_nonempty("screenshot");
  options.report = args.get_nonempty("report");
  options.fixed_dt = args.has_flag("fixed-dt");
  options.paused = args.has_flag("paused");
  if (options.frames < 0) throw UsageError("--frames must be >= 0");
  if (options.width < 64 || options.height < 64 || options.width > 8192 || options.height > 8192)
    throw UsageError("--width and --height must be in [64, 8192]");
  const bool scripted = !args.get_nonempty("replay-drag").empty() || !options.screenshot.empty();
  if (scripted && options.frames == 0)
    throw UsageError("--replay-drag and --screenshot need --frames N");
  // The files the run ends with, checked before the work (the window, the frames).
  for (const auto& [name, path] :
       {std::pair{"screenshot", options.screenshot}, std::pair{"report", options.report}}) {
    try {
      if (!path.empty()) fem::check_writable(path);
    } catch (const fem::WriteError& e) {
      throw UsageError(std::string("--") + name + ": " + e.what());
    }
  }
  if (!args.get("replay-drag").empty()) {
    try {
      options.replay = fv::DragReplay::parse(args.get("replay-drag"), options.frames);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }
  return options;
}

int run_viewer(const fem::ArgParser& args) {
  using namespace fem;
  const Options options = viewer_options(args);
  const int threads = threads_from_args(args);
  const Scene scene = scene_from_args(args);
  fv::SessionSettings settings;
  settings.scene = scene.name;
  settings.material = scene.material;
  settings.damping = scene.damping;
  settings.dt = scene.dt;
  settings.solver = solver_from_args(args);
  settings.threads = thread_count_asked() ? threads : 0;
  auto session = std::make_unique<fv::Session>(scene.mesh, settings, options.chapter);
  std::cout << "fem_viewer: " << scene.name << " on " << scene.mesh.file << " ("
            << scene.mesh.num_nodes() << " nodes), chapter " << options.chapter << ", "
            << (settings.threads > 0 ? std::to_string(threads) + " threads asked"
                                     : std::string("threads not asked (the library's choice)"))
            << " for the parallel chapters\n";
  const Window window(options);
  run(window.handle, session, options);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  fem::ArgParser args("fem_viewer",
                      "Real-time viewer: drag the body with the mouse, switch chapters live.");
  add_viewer_options(args);
  return fem::run_program("fem_viewer",
                          [&] { return args.parse(argc, argv) ? run_viewer(args) : 0; });
}
