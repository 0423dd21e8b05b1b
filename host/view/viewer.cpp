#include "view/viewer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <GLFW/glfw3.h>
#include <vulkan/vulkan_raii.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "base/errors.h"
#include "base/file_watcher.h"
#include "base/interrupt.h"
#include "base/timing.h"
#include "image/display.h"
#include "image/image_file.h"
#include "load/scene_loader.h"
#include "session/failure.h"
#include "session/paths.h"
#include "session/session.h"
#include "view/controls.h"
#include "view/overlay.h"
#include "view/presenter.h"
#include "view/window.h"

namespace vkray::view {
namespace {

using Seconds = std::chrono::duration<double>;

// Work a frame may hold while the user is moving things (so that the window answers within a frame
// or two), and once input has been still for kSettle (more samples a frame, fewer frames to pay for).
constexpr Seconds kInteractiveBudget{0.025};
constexpr Seconds kSettledBudget{0.04};
constexpr Seconds kSettle{0.5};
// How long a frame waits for input when there is nothing to render: the file watcher is polled this often.
constexpr double kIdleWait = 0.05;
// Editors write a file in several steps: a reload waits this long after the last one.
constexpr std::chrono::milliseconds kReloadSettle{50};
constexpr float kExposureStep = 0.5f;

std::filesystem::path absolute_normal(const std::filesystem::path& p) { return std::filesystem::absolute(p).lexically_normal(); }

// One line of what went wrong, or the multi-line shader report (file:line per error).
std::string failure_text(const std::exception_ptr& error) {
  const Failure failure = describe_failure(error);
  return failure.multiline ? failure.message : failure.headline + ": " + failure.message;
}

std::string fixed(double v, int decimals) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", decimals, v);
  return text;
}

std::string rate_text(double per_second) {
  if (per_second >= 1e9) return fixed(per_second / 1e9, 2) + " G";
  if (per_second >= 1e6) return fixed(per_second / 1e6, 2) + " M";
  if (per_second >= 1e3) return fixed(per_second / 1e3, 1) + " k";
  return fixed(per_second, 0) + " ";
}

const std::vector<std::pair<std::string, std::string>> kKeys = {
    {"W / S", "light forward / back"},
    {"A / D", "light left / right"},
    {"Q / E", "light up / down"},
    {"Up / Down", "camera forward / back"},
    {"Left / Right", "turn the camera"},
    {"left drag", "orbit"},
    {"right drag", "pan"},
    {"wheel", "zoom"},
    {"middle click, Shift+click", "focus there (thin lens)"},
    {"I", "integrator: direct / path"},
    {"+ / - / 0", "exposure up / down / reset"},
    {"T", "tone mapper: none, aces, pbr-neutral"},
    {"P", "save the image (-o)"},
    {"F12", "save the window as shown"},
    {"R", "start the accumulation again"},
    {"F1, H", "these keys"},
    {"Tab", "hide or show the overlay"},
    {"Esc", "quit"},
};

class Viewer {
 public:
  explicit Viewer(const ViewerOptions& options);
  ~Viewer();
  int run();

 private:
  void loop();
  // ---- The device and what presents on it ----
  void open_device();
  // What holds the device, released before the session (whose close() checks the validation log).
  void release_device_objects();
  void close_device();
  // After a lost device (the current exception): opens it again, once.
  void reopen_device();

  // ---- The scene and the shaders ----
  void load_scene_file();  // throws what loading throws
  void reload(const std::vector<std::filesystem::path>& changed);
  void watch_current_files();
  bool is_scene_file(const std::filesystem::path& file) const;
  // The scene as the file says, with the viewer's camera, light and integrator.
  std::shared_ptr<const Scene> edited_scene() const;
  // Uploads the edited scene and starts the accumulation again.
  void restart();

  // ---- Input ----
  void handle(const InputEvent& event);
  void key(int key, int mods);
  // Where the camera ray through window point `at` first hits, as a distance along the view
  // direction; nullopt where it hits nothing.
  std::optional<float> hit_depth(glm::dvec2 at);
  float pivot_distance();

  // ---- Frames ----
  void trace(Seconds budget);
  void update_pixels();
  OverlayContent overlay_content() const;
  // The camera as a scene file's "camera" object (controls.h).
  std::string view_json() const;
  void present(bool read_back);
  void save_image();
  void save_window();
  void log_frame(double frame_ms);
  void say(const std::string& message, bool error);

  ViewerOptions options_;
  std::filesystem::path scene_file_, environment_file_, output_;
  std::unique_ptr<Window> window_;
  std::unique_ptr<Session> session_;
  std::unique_ptr<Presenter> presenter_;
  std::unique_ptr<Overlay> overlay_;
  FileWatcher watcher_;

  // The scene file as last loaded without errors, and what the viewer changed of it.
  std::shared_ptr<const Scene> loaded_;
  Camera camera_;
  // Where the camera looks once the viewer has moved it (controls.h, settle): its camera then
  // writes out exactly. Unset: the scene file's own camera.
  std::optional<glm::vec3> look_at_;
  std::optional<glm::vec3> light_position_;  // of the first light, moved by W/S, A/D, Q/E
  Integrator::Type integrator_ = Integrator::Type::direct;
  Steps steps_;
  std::optional<float> pivot_;  // distance from the camera to the point it orbits

  std::optional<DeviceScene> on_device_;
  std::unique_ptr<ProgressiveRender> progressive_;
  bool scene_broken_ = false, shader_broken_ = false, trace_failed_ = false;
  bool needs_restart_ = true;
  double rate_hint_ = 0;
  uint64_t restarts_ = 0;  // accumulations started
  bool reopened_ = false;  // the device was lost once and opened again

  // What the window shows.
  uint32_t width_ = 0, height_ = 0;  // the render's size: the window's framebuffer
  Image image_;
  std::vector<uint8_t> pixels_;
  bool pixels_stale_ = true;
  DisplayTransform display_;
  OverlayContent panels_;  // what the overlay shows besides the status: help, the last message
  bool quit_ = false, save_requested_ = false, window_save_requested_ = false;

  // Mouse drags.
  enum class Drag { none, orbit, pan } drag_ = Drag::none;
  glm::dvec2 drag_at_{0.0};

  // Timing.
  Clock::time_point start_ = Clock::now(), last_input_ = Clock::now() - std::chrono::seconds(10);
  std::optional<Clock::time_point> input_pending_;  // an input that changed the view, not yet on screen
  std::optional<Clock::time_point> reload_pending_;
  double frame_ms_ = 0, samples_per_second_ = 0;
  std::unique_ptr<std::ofstream> frame_log_;
};

Viewer::Viewer(const ViewerOptions& options)
    : options_(options),
      scene_file_(absolute_normal(options.scene)),
      environment_file_(options.environment.empty() ? std::filesystem::path() : absolute_normal(options.environment)),
      output_(options.output),
      display_(options.content.display) {
  check_output_image(output_);  // before the window: a typo costs nothing
  options_.render.aovs = !options_.content.passes.empty();  // accumulated with the image, for an EXR
  options_.session.shader_dir =
      absolute_normal(options_.session.shader_dir.empty() ? default_shader_dir() : options_.session.shader_dir);
  load_scene_file();  // a broken scene is reported before any window opens
  camera_ = loaded_->camera;
  integrator_ = loaded_->integrator.type;
  steps_ = steps_for(*loaded_);
  const ImageSettings image = image_settings(*loaded_, options_.render);
  width_ = image.width;
  height_ = image.height;
  if (!options_.frame_log.empty()) {
    frame_log_ = std::make_unique<std::ofstream>(options_.frame_log);
    if (!*frame_log_) throw OutputError(options_.frame_log.string() + ": cannot be written (--frame-log)");
  }
  window_ = std::make_unique<Window>("vkray view: " + loaded_->name, width_, height_);
  open_device();
  panels_.keys = kKeys;
  watcher_.set_folder(options_.session.shader_dir, {".comp", ".glsl", ".h", ".inc"});
}

Viewer::~Viewer() { close_device(); }

void Viewer::open_device() {
  SessionOptions session_options = options_.session;
  session_options.surface = window_->surface_request();
  session_ = std::make_unique<Session>(session_options);
  std::cerr << "vkray: device " << session_->device_description() << (options_.session.validation ? ", validation on" : "")
            << "\n";
  presenter_ = std::make_unique<Presenter>(session_->context());
  overlay_ = std::make_unique<Overlay>(window_->handle(), session_->context(), *presenter_);
  try {
    session_->compile_shaders();
    shader_broken_ = false;
  } catch (const ShaderError&) {
    if (options_.exit_when_done) throw;  // it would never be done
    say(failure_text(std::current_exception()), true);
    shader_broken_ = true;
  }
  needs_restart_ = true;
}

void Viewer::reopen_device() {
  std::cerr << "vkray: " << failure_text(std::current_exception()) << "; opening the device again\n";
  if (reopened_) throw;  // lost again: it cannot be brought back
  reopened_ = true;
  close_device();
  open_device();
  say("the device was lost and opened again", true);
}

void Viewer::release_device_objects() {
  progressive_.reset();
  on_device_.reset();
  overlay_.reset();
  presenter_.reset();
}

void Viewer::close_device() {
  release_device_objects();
  session_.reset();
}

void Viewer::load_scene_file() {
  auto scene = std::make_shared<const Scene>(load_scene(scene_file_, nullptr, environment_file_));
  for (const auto& warning : scene->warnings) std::cerr << "vkray: warning: " << warning << "\n";
  if (loaded_) {
    // What the file changed wins over what the viewer changed; the rest of the viewer's changes stay.
    const auto same = [](const Camera& a, const Camera& b) {
      return a.position == b.position && a.forward == b.forward && a.up == b.up && a.focal_length == b.focal_length &&
             a.aperture_radius == b.aperture_radius && a.focus_distance == b.focus_distance;
    };
    if (!same(scene->camera, loaded_->camera)) {
      camera_ = scene->camera;
      look_at_.reset();
      pivot_.reset();
    }
    if (scene->integrator.type != loaded_->integrator.type) integrator_ = scene->integrator.type;
    if (scene->lights.empty() || loaded_->lights.empty() || scene->lights[0].position != loaded_->lights[0].position)
      light_position_.reset();
  }
  loaded_ = std::move(scene);
}

std::shared_ptr<const Scene> Viewer::edited_scene() const {
  auto scene = std::make_shared<Scene>(*loaded_);
  scene->camera = camera_;
  scene->integrator.type = integrator_;
  if (light_position_ && !scene->lights.empty()) scene->lights[0].position = *light_position_;
  return scene;
}

void Viewer::restart() {
  needs_restart_ = false;
  ++restarts_;
  trace_failed_ = false;
  if (progressive_ && progressive_->rate() > 0) rate_hint_ = progressive_->rate();
  progressive_.reset();
  if (scene_broken_ || shader_broken_ || !session_->has_shaders()) return;
  try {
    auto scene = edited_scene();
    on_device_ = on_device_ ? session_->upload_changes(*on_device_, std::move(scene)) : session_->upload(std::move(scene));
    RenderOptions render = options_.render;
    render.width = width_;
    render.height = height_;
    progressive_ = session_->start_progressive(*on_device_, render, rate_hint_);
  } catch (const DeviceLostError&) {
    throw;
  } catch (const Cancelled&) {
    throw;
  } catch (...) {  // the shaders do not compile with the scene's code, a scene too large for the device
    if (options_.exit_when_done) throw;  // it would never be done
    say(failure_text(std::current_exception()), true);
    trace_failed_ = true;
  }
}

bool Viewer::is_scene_file(const std::filesystem::path& file) const {
  if (file == scene_file_ || file == environment_file_) return true;
  return std::any_of(loaded_->referenced_files.begin(), loaded_->referenced_files.end(),
                     [&](const auto& r) { return absolute_normal(r) == file; });
}

void Viewer::watch_current_files() {
  std::vector<std::filesystem::path> files = session_->shader_sources();
  files.push_back(scene_file_);
  if (!environment_file_.empty()) files.push_back(environment_file_);
  files.insert(files.end(), loaded_->referenced_files.begin(), loaded_->referenced_files.end());
  try {
    watcher_.set_files(files);
  } catch (const Error&) {  // a folder past the inotify limit: watching goes on without it
    say(failure_text(std::current_exception()), true);
  }
}

void Viewer::reload(const std::vector<std::filesystem::path>& changed) {
  const bool scene_changed = std::any_of(changed.begin(), changed.end(), [&](const auto& f) { return is_scene_file(f); });
  const bool shader_changed = std::any_of(changed.begin(), changed.end(), [&](const auto& f) { return !is_scene_file(f); });
  std::string line;
  if (scene_changed) {
    try {
      const auto start = Clock::now();
      load_scene_file();
      on_device_.reset();  // uploaded again, the geometry may have changed
      rate_hint_ = 0;
      steps_ = steps_for(*loaded_);
      scene_broken_ = false;
      line += "scene " + fixed(ms_since(start), 0) + " ms";
    } catch (const Cancelled&) {
      throw;
    } catch (...) {
      say(failure_text(std::current_exception()), true);
      std::cerr << "vkray: " << failure_text(std::current_exception()) << "\n";
      scene_broken_ = true;
      line += "scene has errors";
    }
  }
  if (shader_changed) {
    try {
      const Session::ShaderCompile compiled = session_->compile_shaders();
      shader_broken_ = false;
      line += std::string(line.empty() ? "" : ", ") + "compile " + fixed(compiled.seconds * 1e3, 0) + " ms" +
              (compiled.spirv_changed ? "" : " (SPIR-V unchanged)");
    } catch (const Cancelled&) {
      throw;
    } catch (const DeviceLostError&) {
      throw;
    } catch (...) {
      const std::string text = failure_text(std::current_exception());
      say(text, true);
      std::cerr << (describe_failure(std::current_exception()).multiline ? "" : "vkray: ") << text << "\n";
      shader_broken_ = true;
      line += std::string(line.empty() ? "" : ", ") + "shader has errors";
    }
  }
  if (!scene_broken_ && !shader_broken_) {
    panels_.message.clear();
    needs_restart_ = true;
    reload_pending_ = Clock::now();
  }
  std::cerr << "vkray: reload: " << line << (scene_broken_ || shader_broken_ ? "; the last good image stays" : "") << "\n";
  watch_current_files();
}

std::optional<float> Viewer::hit_depth(glm::dvec2 at) {
  if (!on_device_ || scene_broken_ || shader_broken_) return std::nullopt;
  const glm::dvec2 window_size = glm::dvec2(window_->framebuffer_size());
  if (at.x < 0 || at.y < 0 || at.x >= window_size.x || at.y >= window_size.y || at.x >= width_ || at.y >= height_)
    return std::nullopt;
  RenderOptions one = options_.render;
  one.width = width_;
  one.height = height_;
  one.samples_per_pixel = 1;
  one.aovs = true;
  one.inline_scene = InlineScene::never;  // the pipeline with the passes, without compiling the scene in
  one.region = PixelRegion{uint32_t(at.x), uint32_t(at.y), uint32_t(at.x) + 1, uint32_t(at.y) + 1};
  try {
    const RenderResult result = session_->render(*on_device_, one);
    const float depth = result.aovs->depth[0];
    if (!std::isfinite(depth)) return std::nullopt;
    return glm::dot(result.aovs->position[0] - camera_.position, camera_.forward);
  } catch (const DeviceLostError&) {
    throw;
  } catch (...) {
    say(failure_text(std::current_exception()), true);
    return std::nullopt;
  }
}

float Viewer::pivot_distance() {
  if (!pivot_) pivot_ = hit_depth(glm::dvec2(width_ / 2.0, height_ / 2.0)).value_or(std::max(loaded_->extent(), 1e-3f));
  return *pivot_;
}

void Viewer::key(int key, int mods) {
  const auto move_light_by = [&](glm::vec3 steps) {
    if (loaded_->lights.empty()) return say("the scene has no point or spot light to move", false);
    Light light = loaded_->lights[0];
    if (light_position_) light.position = *light_position_;
    if (!move_light(light, camera_, steps, steps_.move)) return say("the first light is directional: it has no position", false);
    light_position_ = light.position;
    needs_restart_ = true;
  };
  const auto camera_changed = [&] {
    look_at_ = settle(camera_, pivot_.value_or(std::max(loaded_->extent(), 1e-3f)));
    needs_restart_ = true;
    pivot_.reset();
  };
  switch (key) {
    case GLFW_KEY_ESCAPE: quit_ = true; break;
    case GLFW_KEY_W: move_light_by({0, 0, 1}); break;
    case GLFW_KEY_S: move_light_by({0, 0, -1}); break;
    case GLFW_KEY_A: move_light_by({-1, 0, 0}); break;
    case GLFW_KEY_D: move_light_by({1, 0, 0}); break;
    case GLFW_KEY_Q: move_light_by({0, 1, 0}); break;
    case GLFW_KEY_E: move_light_by({0, -1, 0}); break;
    case GLFW_KEY_UP: move_camera(camera_, steps_.move); camera_changed(); break;
    case GLFW_KEY_DOWN: move_camera(camera_, -steps_.move); camera_changed(); break;
    case GLFW_KEY_LEFT: turn_camera(camera_, -steps_.turn); camera_changed(); break;
    case GLFW_KEY_RIGHT: turn_camera(camera_, steps_.turn); camera_changed(); break;
    case GLFW_KEY_I:
      integrator_ = integrator_ == Integrator::Type::direct ? Integrator::Type::path : Integrator::Type::direct;
      needs_restart_ = true;
      rate_hint_ = 0;  // the other integrator's rate says nothing of this one's: start from a band
      break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD:
      display_.exposure = std::min(display_.exposure + kExposureStep, kMaxExposure);
      pixels_stale_ = true;
      break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT:
      display_.exposure = std::max(display_.exposure - kExposureStep, -kMaxExposure);
      pixels_stale_ = true;
      break;
    case GLFW_KEY_0:
    case GLFW_KEY_KP_0:
      display_.exposure = 0.0f;
      pixels_stale_ = true;
      break;
    case GLFW_KEY_T:
      display_.tonemap = display_.tonemap == Tonemap::none ? Tonemap::aces
                         : display_.tonemap == Tonemap::aces ? Tonemap::pbr_neutral : Tonemap::none;
      pixels_stale_ = true;
      break;
    case GLFW_KEY_P: save_requested_ = true; break;
    case GLFW_KEY_F12: window_save_requested_ = true; break;
    case GLFW_KEY_R: needs_restart_ = true; break;
    case GLFW_KEY_F1:
    case GLFW_KEY_H: panels_.show_help = !panels_.show_help; break;
    case GLFW_KEY_TAB: panels_.show = !panels_.show; break;
    default: break;
  }
  static_cast<void>(mods);
}

void Viewer::handle(const InputEvent& event) {
  // Window coordinates to pixels (they differ on a display that scales).
  const glm::dvec2 scale = [&] {
    int w = 0, h = 0;
    glfwGetWindowSize(window_->handle(), &w, &h);
    const glm::dvec2 fb(window_->framebuffer_size());
    return w > 0 && h > 0 ? fb / glm::dvec2(w, h) : glm::dvec2(1.0);
  }();
  const bool before = needs_restart_;
  switch (event.kind) {
    case InputEvent::Kind::key:
      if (event.action == GLFW_PRESS || event.action == GLFW_REPEAT) key(event.key, event.mods);
      break;
    case InputEvent::Kind::button: {
      const glm::dvec2 at = event.position * scale;
      const bool focus = event.key == GLFW_MOUSE_BUTTON_MIDDLE ||
                         (event.key == GLFW_MOUSE_BUTTON_LEFT && (event.mods & GLFW_MOD_SHIFT));
      if (event.action == GLFW_PRESS && focus) {
        if (const auto depth = hit_depth(at)) {
          camera_.focus_distance = *depth;
          // The camera has changed: from now on it is written out as the viewer holds it.
          if (!look_at_) look_at_ = settle(camera_, std::max(loaded_->extent(), 1e-3f));
          needs_restart_ = true;
          const std::string text = "focus distance " + fixed(*depth, 4) +
                                   (camera_.aperture_radius > 0.0f ? "" : " (the camera is a pinhole: give it an aperture_radius to see it)");
          say(text, false);
          std::cerr << "vkray: " << text << "\n";
        }
      } else if (event.action == GLFW_PRESS) {
        drag_ = event.key == GLFW_MOUSE_BUTTON_LEFT ? Drag::orbit : event.key == GLFW_MOUSE_BUTTON_RIGHT ? Drag::pan : Drag::none;
        drag_at_ = at;
        if (drag_ != Drag::none) pivot_distance();
      } else if (event.action == GLFW_RELEASE) {
        drag_ = Drag::none;
      }
      break;
    }
    case InputEvent::Kind::cursor: {
      const glm::dvec2 at = event.position * scale;
      const glm::dvec2 delta = at - drag_at_;
      drag_at_ = at;
      if (drag_ == Drag::orbit && delta != glm::dvec2(0.0)) {
        orbit(camera_, pivot_distance(), float(delta.x) * steps_.orbit, -float(delta.y) * steps_.orbit);
        look_at_ = settle(camera_, pivot_distance());
        needs_restart_ = true;
      } else if (drag_ == Drag::pan && delta != glm::dvec2(0.0)) {
        pan(camera_, pivot_distance(), glm::vec2(delta), height_);
        look_at_ = settle(camera_, pivot_distance());
        needs_restart_ = true;
      }
      break;
    }
    case InputEvent::Kind::scroll:
      if (event.position.y != 0.0) {
        pivot_ = zoom(camera_, pivot_distance(), float(event.position.y), 1e-4f * std::max(loaded_->extent(), 1e-3f));
        look_at_ = settle(camera_, *pivot_);
        needs_restart_ = true;
      }
      break;
  }
  last_input_ = Clock::now();
  if ((needs_restart_ && !before) || pixels_stale_) input_pending_ = input_pending_.value_or(Clock::now());
}

void Viewer::trace(Seconds budget) {
  if (!progressive_ || progressive_->done() || trace_failed_) return;
  const uint32_t samples = progressive_->samples(), rows = progressive_->rows_ahead();
  const auto start = Clock::now();
  try {
    progressive_->advance(budget);
  } catch (const DeviceLostError&) {
    throw;
  } catch (const Cancelled&) {
    throw;
  } catch (...) {  // a tile past its timeout (a shader that loops), a validation message
    if (options_.exit_when_done) throw;  // it would never be done
    say(failure_text(std::current_exception()), true);
    std::cerr << "vkray: " << failure_text(std::current_exception()) << "\n";
    trace_failed_ = true;
    return;
  }
  const double pixel_samples =
      (double(progressive_->samples()) - samples) * width_ * height_ + (double(progressive_->rows_ahead()) - rows) * width_;
  const double seconds = std::max(seconds_since(start), 1e-6);
  const double rate = pixel_samples / seconds;
  samples_per_second_ = samples_per_second_ > 0 ? 0.8 * samples_per_second_ + 0.2 * rate : rate;
  progressive_->image(image_);
  pixels_stale_ = true;
}

void Viewer::update_pixels() {
  if (!pixels_stale_) return;
  pixels_stale_ = false;
  if (image_.width != width_ || image_.height != height_) return;  // nothing rendered at this size yet
  pixels_.resize(size_t(width_) * height_ * 4);
  const bool bgra = presenter_->order() == PixelOrder::bgra;
  // On every core: between two steps the device waits for this (on lavapipe, its threads are the cores).
  tbb::parallel_for(tbb::blocked_range<size_t>(0, image_.pixels.size(), 4096), [&](const tbb::blocked_range<size_t>& range) {
    uint8_t rgb[3];
    for (size_t i = range.begin(); i < range.end(); ++i) {
      display_.encode(image_.pixels[i], rgb);
      uint8_t* out = &pixels_[i * 4];
      out[0] = rgb[bgra ? 2 : 0];
      out[1] = rgb[1];
      out[2] = rgb[bgra ? 0 : 2];
      out[3] = 255;
    }
  });
}

std::string Viewer::view_json() const {
  if (look_at_) return camera_json(camera_, *look_at_);
  return camera_json(camera_, camera_.position + camera_.forward * std::max(loaded_->extent(), 1e-3f));
}

OverlayContent Viewer::overlay_content() const {
  OverlayContent content = panels_;
  const bool path = integrator_ == Integrator::Type::path;
  content.status.push_back(loaded_->name + "   " + std::to_string(width_) + " x " + std::to_string(height_) + "   " +
                           (path ? "path" : "direct"));
  if (progressive_) {
    std::string samples = "samples " + std::to_string(progressive_->samples()) + " / " + std::to_string(progressive_->target());
    if (progressive_->done()) samples += "  (done: as vkray render --spp " + std::to_string(progressive_->target()) + ")";
    content.status.push_back(samples);
  } else {
    content.status.push_back(scene_broken_ || shader_broken_ || trace_failed_ ? "not rendering: see the message below"
                                                                               : "samples -");
  }
  content.status.push_back("frame " + fixed(frame_ms_, 1) + " ms   " + rate_text(samples_per_second_) + "samples/s");
  content.status.push_back("device " + session_->device_name());
  content.status.push_back("exposure " + std::string(display_.exposure >= 0 ? "+" : "") + fixed(display_.exposure, 1) +
                           " EV   tone mapper " + std::string(tonemap_name(display_.tonemap)));
  content.camera_json = view_json();
  return content;
}

void Viewer::present(bool read_back) {
  const glm::uvec2 size = window_->framebuffer_size();
  update_pixels();
  overlay_->build(overlay_content());
  std::vector<uint8_t> window_pixels;
  const bool have = image_.width == width_ && image_.height == height_ && !pixels_.empty();
  const bool shown = presenter_->present(vk::Extent2D(size.x, size.y), have ? pixels_.data() : nullptr, width_, height_,
                                         [&](vk::CommandBuffer cb) { overlay_->record(cb); },
                                         read_back ? &window_pixels : nullptr);
  overlay_->set_image_count(presenter_->min_image_count());
  if (read_back && shown) {
    if (window_pixels.empty()) return say("this device cannot read its window's images back", true);
    const vk::Extent2D extent = presenter_->extent();
    Image window(extent.width, extent.height);
    for (size_t i = 0; i < window.pixels.size(); ++i)
      for (int c = 0; c < 3; ++c) window.pixels[i][c] = decode_srgb8(window_pixels[i * 4 + size_t(c)]);
    std::filesystem::path file = output_;
    file.replace_filename(output_.stem().string() + "-window.png");
    try {
      write_png(window, file);
      say("wrote " + file.string() + " (the window as shown)", false);
      std::cerr << "vkray: wrote " << file.string() << "\n";
    } catch (const Error&) {
      say(failure_text(std::current_exception()), true);
    }
  }
}

void Viewer::save_image() {
  if (!progressive_ || (progressive_->samples() == 0 && progressive_->rows_ahead() == 0))
    return say("nothing rendered yet to save", true);
  Image image;
  progressive_->image(image);
  if (progressive_->samples() == 0) return say("not saved: the first sample is not done yet", true);
  OutputContent content = options_.content;
  // A PNG shows what the window shows; EXR and PFM files hold linear radiance.
  content.display = image_file_type(output_) == ImageFileType::png ? display_ : DisplayTransform{};
  try {
    // Rows that already have one more sample are saved with it: the image is each pixel's mean.
    Aovs passes;
    if (progressive_->has_aovs()) progressive_->aovs(passes);
    write_render_image(output_, image, progressive_->has_aovs() ? &passes : nullptr, content);
    const std::string text = "wrote " + output_.string() + " (" + std::to_string(progressive_->samples()) + " of " +
                             std::to_string(progressive_->target()) + " samples)";
    say(text, false);
    std::cerr << "vkray: " << text << "\n";
    // The view, so that `vkray render` can render it: the camera and the first light as they are now.
    // Before any move the camera is the scene file's own (which written out again would not read back
    // to the same bits).
    std::cerr << "vkray: view: " << (look_at_ ? view_json() : std::string("the scene file's camera"));
    if (!loaded_->lights.empty() && loaded_->lights[0].type != Light::Type::directional) {
      std::cerr << ", first light at " << point_json(light_position_.value_or(loaded_->lights[0].position));
      if (loaded_->lights[0].type == Light::Type::spot) std::cerr << " pointing " << point_json(loaded_->lights[0].direction);
    }
    std::cerr << ", integrator " << (integrator_ == Integrator::Type::path ? "path" : "direct") << "\n";
  } catch (const Error&) {
    if (options_.exit_when_done) throw;  // the one thing asked for failed
    say(failure_text(std::current_exception()), true);
    std::cerr << "vkray: " << failure_text(std::current_exception()) << "\n";
  }
}

void Viewer::say(const std::string& message, bool error) {
  panels_.message = message;
  panels_.message_is_error = error;
}

void Viewer::log_frame(double frame_ms) {
  if (!frame_log_) return;
  const double t = seconds_between(start_, Clock::now());
  const double unix_time = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  *frame_log_ << "{\"t\": " << fixed(t, 4) << ", \"time\": " << fixed(unix_time, 4) << ", \"frame_ms\": " << fixed(frame_ms, 2)
              << ", \"samples\": " << (progressive_ ? progressive_->samples() : 0)
              << ", \"rows_ahead\": " << (progressive_ ? progressive_->rows_ahead() : 0)
              << ", \"target\": " << (progressive_ ? progressive_->target() : 0) << ", \"restarts\": " << restarts_
              << ", \"width\": " << width_
              << ", \"height\": " << height_ << ", \"samples_per_second\": " << fixed(samples_per_second_, 0);
  if (input_pending_) *frame_log_ << ", \"input_ms\": " << fixed(ms_since(*input_pending_), 2);
  if (reload_pending_) *frame_log_ << ", \"reload_ms\": " << fixed(ms_since(*reload_pending_), 2);
  *frame_log_ << "}\n" << std::flush;
}

int Viewer::run() {
  watch_current_files();
  std::cerr << "vkray: viewing " << loaded_->name << "; F1 lists the keys, Esc quits\n";
  try {
    loop();
  } catch (const Cancelled&) {  // Ctrl-C in the terminal: the window closes as if asked to
  }
  // As for render: the device's teardown can raise validation messages (objects left alive), and
  // they must fail the command.
  release_device_objects();
  session_->close();
  std::cerr << "vkray: closed\n";
  return kExitOk;
}

void Viewer::loop() {
  while (!quit_ && !window_->close_requested()) {
    const auto frame_start = Clock::now();
    const bool busy = progressive_ && !progressive_->done() && !trace_failed_;
    window_->poll(busy || needs_restart_ ? 0.0 : kIdleWait);
    throw_if_interrupted();
    // The window's size is the render's.
    const glm::uvec2 size = window_->framebuffer_size();
    const glm::uvec2 render_size = glm::min(size, glm::uvec2(kMaxImageSide));
    if (size.x > 0 && size.y > 0 && (render_size.x != width_ || render_size.y != height_)) {
      width_ = render_size.x;
      height_ = render_size.y;
      needs_restart_ = true;
    }
    try {
      for (const InputEvent& event : window_->take_events()) handle(event);
      if (const auto changed = watcher_.poll(kReloadSettle); !changed.empty()) reload(changed);
      if (needs_restart_) restart();
      trace(Clock::now() - last_input_ < kSettle ? kInteractiveBudget : kSettledBudget);
      if (save_requested_) {
        save_requested_ = false;
        save_image();
      }
      if (size.x == 0 || size.y == 0) continue;  // minimised: nothing to show
      present(std::exchange(window_save_requested_, false));
    } catch (const DeviceLostError&) {
      reopen_device();
      continue;
    } catch (const vk::DeviceLostError&) {  // from the swapchain or the overlay, which call Vulkan directly
      reopen_device();
      continue;
    } catch (const TimeoutError&) {  // a frame or a step waited past its time: shown, and the next change tries again
      if (options_.exit_when_done) throw;
      say(failure_text(std::current_exception()), true);
      std::cerr << "vkray: " << failure_text(std::current_exception()) << "\n";
      trace_failed_ = true;
      continue;
    }
    frame_ms_ = ms_since(frame_start);
    if (input_pending_ || reload_pending_) {
      log_frame(frame_ms_);
      input_pending_.reset();
      reload_pending_.reset();
    } else if (busy) {
      log_frame(frame_ms_);
    }
    if (options_.exit_when_done && progressive_ && progressive_->done()) {
      save_image();
      break;
    }
  }
}

}  // namespace

int run_viewer(const ViewerOptions& options) { return Viewer(options).run(); }

}  // namespace vkray::view
