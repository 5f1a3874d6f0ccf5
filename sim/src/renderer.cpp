#include "pvb/sim/renderer.hpp"

#include "pvb/common/error.hpp"

namespace pvb::sim {

Renderer::Renderer(const mjModel* model, GlBackend backend, int width, int height)
    : width_(width), height_(height) {
  if (width > model->vis.global.offwidth || height > model->vis.global.offheight)
    throw ConfigError("model", "visual.global.offwidth/offheight",
                      "at least " + std::to_string(width) + "x" + std::to_string(height),
                      std::to_string(model->vis.global.offwidth) + "x" + std::to_string(model->vis.global.offheight));
  gl_ = GlContext::create(backend, width, height);
  mjr_defaultContext(&con_);
  mjv_defaultScene(&scene_);
  mjv_defaultOption(&option_);
  mjv_defaultCamera(&camera_);
  mjv_makeScene(model, &scene_, 4000);
  mjr_makeContext(model, &con_, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &con_);
  if (con_.currentBuffer != mjFB_OFFSCREEN) {
    mjr_freeContext(&con_);
    mjv_freeScene(&scene_);
    throw UnavailableError(std::string("GL backend ") + to_string(gl_->backend()) +
                           ": MuJoCo could not use its off-screen buffer");
  }
  rgb_buf_.resize(static_cast<std::size_t>(width) * height * 3);
  depth_buf_.resize(static_cast<std::size_t>(width) * height);
}

Renderer::~Renderer() {
  // MuJoCo frees its GL objects in the current context: make it ours.
  try {
    gl_->make_current();
  } catch (const UnavailableError&) {
    // nothing to free into; the context goes with gl_
  }
  mjr_freeContext(&con_);
  mjv_freeScene(&scene_);
}

void Renderer::set_shadows(bool on) { scene_.flags[mjRND_SHADOW] = on ? 1 : 0; }

void Renderer::render(const mjModel* model, mjData* data, int camera_id, cv::Mat* rgb, cv::Mat* depth_m) {
  // Another renderer of this process (or none, once it was destroyed) may
  // hold the thread's current context.
  gl_->make_current();
  camera_.type = mjCAMERA_FIXED;
  camera_.fixedcamid = camera_id;
  mjv_updateScene(model, data, &option_, nullptr, &camera_, mjCAT_ALL, &scene_);
  const mjrRect viewport{0, 0, width_, height_};
  mjr_render(viewport, &scene_, &con_);
  mjr_readPixels(rgb ? rgb_buf_.data() : nullptr, depth_m ? depth_buf_.data() : nullptr, viewport, &con_);

  if (rgb != nullptr) {
    rgb->create(height_, width_, CV_8UC3);
    for (int r = 0; r < height_; ++r) {
      const unsigned char* src = rgb_buf_.data() + static_cast<std::size_t>(height_ - 1 - r) * width_ * 3;
      std::copy(src, src + static_cast<std::size_t>(width_) * 3, rgb->ptr<unsigned char>(r));
    }
  }
  if (depth_m != nullptr) {
    const double extent = model->stat.extent;
    const double n = model->vis.map.znear * extent;
    const double f = model->vis.map.zfar * extent;
    depth_m->create(height_, width_, CV_32FC1);
    for (int r = 0; r < height_; ++r) {
      const float* src = depth_buf_.data() + static_cast<std::size_t>(height_ - 1 - r) * width_;
      float* dst = depth_m->ptr<float>(r);
      for (int c = 0; c < width_; ++c) dst[c] = depth_from_buffer(src[c], n, f);
    }
  }
}

}  // namespace pvb::sim
