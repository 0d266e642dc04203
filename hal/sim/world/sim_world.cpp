#include "hal/sim/world/sim_world.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "hal/sim/textured_model_files.hpp"
#include "hal/sim/world/renderer.hpp"
#include "recog/camera/calibration_yaml.hpp"
#include "recog/camera/table_yaml.hpp"
#include "tables/model_files.hpp"

namespace sh::render {
namespace {

// R'G'B' to Y'CbCr, BT.601 full range, as a colour sensor's ISP delivers NV12: Y' per pixel,
// Cb/Cr of each 2 x 2 block's mean colour (edge blocks of odd sizes over what they cover).
void RgbToNv12(ImageView<const Rgb8> rgb, GrayView y_plane, ImageView<CbCr8> chroma) {
  auto byte = [](float v) {
    return static_cast<uint8_t>(std::lround(std::min(255.0f, std::max(0.0f, v))));
  };
  for (int y = 0; y < rgb.height; ++y) {
    for (int x = 0; x < rgb.width; ++x) {
      const Rgb8 p = rgb.at(x, y);
      y_plane.at(x, y) = byte(0.299f * p.r + 0.587f * p.g + 0.114f * p.b);
    }
  }
  for (int cy = 0; cy < chroma.height; ++cy) {
    for (int cx = 0; cx < chroma.width; ++cx) {
      float r = 0, g = 0, b = 0;
      int n = 0;
      for (int y = 2 * cy; y < std::min(2 * cy + 2, rgb.height); ++y) {
        for (int x = 2 * cx; x < std::min(2 * cx + 2, rgb.width); ++x, ++n) {
          const Rgb8 p = rgb.at(x, y);
          r += p.r, g += p.g, b += p.b;
        }
      }
      r /= float(n), g /= float(n), b /= float(n);
      chroma.at(cx, cy) = CbCr8{byte(128.0f - 0.168736f * r - 0.331264f * g + 0.5f * b),
                                byte(128.0f + 0.5f * r - 0.418688f * g - 0.081312f * b)};
    }
  }
}

// The rig as its files carry it. A recording writes the calibration and the table pose as text,
// and a replay reads them back, where the readers replace each rotation by the nearest exact one.
// The rig is taken through that round trip three times: the first projection moves the
// calibration's float-derived rotation by about 1e-7, the second by about 1e-16, the third not
// at all, so a replay recognises with the numbers the simulator recognised with (the table
// pose, kept in float, need not reach an exact fixed point; tests/python/test_replay.py checks
// the replayed poses).
Status SnapRigToFiles(StereoCalibration* calib, RigidTransform* left_T_table) {
  std::vector<char> text(size_t{16} * 1024);
  for (int round = 0; round < 3; ++round) {
    Result<size_t> n = WriteCalibrationYaml(*calib, text.data(), text.size());
    if (!n.ok()) return n.status().WithContext("the simulator's calibration");
    Result<StereoCalibration> read = ParseCalibrationYaml(text.data(), *n);
    if (!read.ok()) return read.status().WithContext("the simulator's calibration");
    n = WriteTableYaml(*left_T_table, text.data(), text.size());
    if (!n.ok()) return n.status().WithContext("the simulator's table pose");
    Result<RigidTransform> table = ParseTableYaml(text.data(), *n);
    if (!table.ok()) return table.status().WithContext("the simulator's table pose");
    *calib = *read;
    *left_T_table = *table;
  }
  return Status::Ok();
}

}  // namespace

void SimWorld::Configure(const SimWorldConfig& config) {
  config_ = config;
  n_scenes_ = 0;
}

Status SimWorld::EnsureBuilt() {
  if (built()) return Status::Ok();
  return BuildNow();  // sets n_scenes_ only when complete
}

Status SimWorld::BuildNow() {
  const SimWorldConfig& config = config_;
  if (config.scenes < 1 || config.scenes > kMaxSimScenes) {
    return Status::Error(StatusCode::kOutOfRange, "sim scenes %d outside 1..%d", config.scenes,
                         kMaxSimScenes);
  }
  SH_RETURN_IF_ERROR(LoadModelFolder(config.models_dir, &models_));
  SH_RETURN_IF_ERROR(LoadModelColours(config.models_dir, models_, &colours_));
  if (config.colour_dir[0] != '\0') {
    std::vector<Model> parts;
    std::vector<ModelColour> part_colours;
    SH_RETURN_IF_ERROR(LoadModelFolder(config.colour_dir, &parts));
    SH_RETURN_IF_ERROR(LoadModelColours(config.colour_dir, parts, &part_colours));
    for (size_t i = 0; i < parts.size(); ++i) {
      if (!part_colours[i].coloured) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "%s/%s.obj names no material with a diffuse colour (Kd)",
                             config.colour_dir, parts[i].name);
      }
    }
    models_.insert(models_.end(), parts.begin(), parts.end());
    colours_.insert(colours_.end(), part_colours.begin(), part_colours.end());
  }
  colour_ = AnyColoured(colours_);
  n_plain_ = model_count();
  printed_.clear();
  if (config.printed_dir[0] != '\0') {
    std::vector<std::string> names;
    SH_RETURN_IF_ERROR(ModelFolderNames(config.printed_dir, &names));
    for (const std::string& name : names) {
      Result<TexturedModel> m =
          LoadTexturedModelFile(std::string(config.printed_dir) + "/" + name + ".obj");
      if (!m.ok()) return m.status();
      if (!m->texturing.textured()) {
        return Status::Error(StatusCode::kInvalidArgument, "%s/%s.obj has no printed face",
                             config.printed_dir, name.c_str());
      }
      models_.push_back(m->model);
      colours_.push_back(ModelColour{});
      printed_.push_back(std::move(*m));
    }
    if (model_count() > kMaxWorldModels) {
      return Status::Error(StatusCode::kOutOfRange, "more than %d models in the sim world",
                           kMaxWorldModels);
    }
  }
  prints_.clear();
  prints_.reserve(printed_.size());
  for (const TexturedModel& t : printed_) prints_.push_back(PrintOf(t));
  ScenarioParams params;
  params.n_objects = config.objects;
  params.background = config.light_background ? Background::kLight : Background::kDark;
  scenes_.reset(new GeneratedScene[config.scenes]);
  uint64_t seed = config.seed;
  for (int i = 0; i < config.scenes; ++i) {
    // Some seeds cannot place the objects in view; the next seeds are tried (deterministic).
    Result<GeneratedScene> g = GenerateScene(seed++, params, models_.data(), model_count());
    for (int attempt = 0; !g.ok() && attempt < 16; ++attempt) {
      g = GenerateScene(seed++, params, models_.data(), model_count());
    }
    if (!g.ok()) {
      return g.status().WithContext("sim scene %d (seed %llu)", i,
                                    static_cast<unsigned long long>(seed - 1));
    }
    scenes_[i] = *g;
    // The cameras stay where they were bolted: every later scene is seen from scene 0's tilt, so
    // all scenes share one table pose (the firmware bounds and the one-camera fallback use it).
    if (i == 0) params.tilt_deg = g->tilt_deg;
    PaintColourParts(colours_, &scenes_[i].scene);
    for (SceneObject& o : scenes_[i].scene.objects) {
      if (!is_printed(o.model_index)) continue;
      o.albedo = 0.95f;  // the print sets the reflectance
      o.print = &prints_[size_t(o.model_index - n_plain_)];
    }
    const StereoCalibration& c0 = scenes_[0].calib;
    const StereoCalibration& ci = scenes_[i].calib;
    if (ci.left.width != c0.left.width || ci.left.height != c0.left.height ||
        !ci.right_R_left.isApprox(c0.right_R_left, 1e-4) ||
        !ci.right_t_left_mm.isApprox(c0.right_t_left_mm, 1e-4) ||
        !scenes_[i].scene.left_T_table.R.isApprox(scenes_[0].scene.left_T_table.R, 1e-4)) {
      return Status::Error(StatusCode::kInternal, "sim scene %d uses a different rig", i);
    }
    // One calibration for every scene (the rigs agree up to float rounding).
    if (i == 0) {
      SH_RETURN_IF_ERROR(SnapRigToFiles(&scenes_[0].calib, &scenes_[0].scene.left_T_table));
    }
    scenes_[i].calib = c0;
  }
  width_ = scenes_[0].calib.left.width;
  height_ = scenes_[0].calib.left.height;
  const size_t per_image = size_t(width_) * size_t(height_);
  const int cw = (width_ + 1) / 2, ch = (height_ + 1) / 2;
  image_bytes_ = per_image + (colour_ ? 2 * size_t(cw) * size_t(ch) : 0);
  pixels_.reset(new uint8_t[image_bytes_ * 2 * size_t(config.scenes)]);
  std::vector<Rgb8> rgb[2];
  if (colour_) rgb[0].resize(per_image), rgb[1].resize(per_image);
  for (int i = 0; i < config.scenes; ++i) {
    uint8_t* images[2] = {pixels_.get() + image_bytes_ * 2 * size_t(i),
                          pixels_.get() + image_bytes_ * (2 * size_t(i) + 1)};
    RenderTargets targets[2];
    for (int k = 0; k < 2; ++k) {
      if (colour_) {
        targets[k].rgb = {rgb[k].data(), width_, height_, width_};
      } else {
        targets[k].image = {images[k], width_, height_, width_};
      }
    }
    SH_RETURN_IF_ERROR(RenderStereo(scenes_[i].scene, models_.data(), model_count(),
                                    scenes_[i].calib, targets[0], targets[1]));
    if (!colour_) continue;
    for (int k = 0; k < 2; ++k) {
      RgbToNv12(ImageView<const Rgb8>{rgb[k].data(), width_, height_, width_},
                GrayView{images[k], width_, height_, width_},
                ImageView<CbCr8>{reinterpret_cast<CbCr8*>(images[k] + per_image), cw, ch, cw});
    }
  }
  left_T_table_ = scenes_[0].scene.left_T_table;
  n_scenes_ = config.scenes;  // last: built() means complete
  return Status::Ok();
}

Result<StereoCalibration> SimWorld::Calibration() {
  SH_RETURN_IF_ERROR(
      EnsureBuilt().WithContext("the simulator's rig is unknown until its world is built"));
  return scenes_[0].calib;
}

Status SimWorld::Open(int* width, int* height) {
  SH_RETURN_IF_ERROR(EnsureBuilt().WithContext("simulator world"));
  *width = width_;
  *height = height_;
  return Status::Ok();
}

Status SimWorld::Render(uint64_t frame_index, GrayView left, GrayView right) {
  const uint8_t* src = pixels_.get() + image_bytes_ * 2 * size_t(SceneOfFrame(frame_index));
  for (int y = 0; y < height_; ++y) {
    std::memcpy(left.row(y), src + size_t(y) * width_, size_t(width_));
    std::memcpy(right.row(y), src + image_bytes_ + size_t(y) * width_, size_t(width_));
  }
  return Status::Ok();
}

Status SimWorld::RenderNv12(uint64_t frame_index, const hal::Nv12Target& left,
                            const hal::Nv12Target& right) {
  if (!colour_) {
    return Status::Error(StatusCode::kFailedPrecondition, "the sim world renders grey frames");
  }
  SH_RETURN_IF_ERROR(Render(frame_index, left.y, right.y));
  const uint8_t* src = pixels_.get() + image_bytes_ * 2 * size_t(SceneOfFrame(frame_index));
  const size_t per_image = size_t(width_) * size_t(height_);
  const int cw = (width_ + 1) / 2, ch = (height_ + 1) / 2;
  const hal::Nv12Target* targets[2] = {&left, &right};
  for (int k = 0; k < 2; ++k) {
    const CbCr8* chroma = reinterpret_cast<const CbCr8*>(src + image_bytes_ * k + per_image);
    for (int y = 0; y < ch; ++y) {
      std::memcpy(targets[k]->cbcr.row(y), chroma + size_t(y) * cw, sizeof(CbCr8) * size_t(cw));
    }
  }
  return Status::Ok();
}

}  // namespace sh::render
