// A glTF 2.0 file's node animation, sampled at any time (gltf_animation.h). The file goes through
// the loader's checks and rules (gltf_model.h); the sampling follows the glTF 2.0 specification's
// "Animations" section and its appendix on interpolation.
#include "core/scene/gltf_animation.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

#include "core/scene/asset_error.h"
#include "core/scene/gltf_limits.h"
#include "core/scene/gltf_model.h"

namespace arpipe {
// Named, not anonymous: GltfAnimation::Impl holds them (a unity batch warns of anonymous ones).
namespace gltf_animation_keys {

enum class AnimatedProperty { Translation, Rotation, Scale };
enum class KeyInterpolation { Step, Linear, CubicSpline };

// One sampler's keys as a channel of one property reads them: times (seconds, strictly increasing)
// and values (3 or 4 components; CUBICSPLINE: in-tangent, value, out-tangent per key).
struct PropertyTrack {
  AnimatedProperty property = AnimatedProperty::Translation;
  KeyInterpolation interpolation = KeyInterpolation::Linear;
  std::shared_ptr<const std::vector<float>> times;
  std::vector<float> values;
  size_t components = 3;
  std::string where;  // "animation 0 channel 2 (sampler 1)", for messages
};

}  // namespace gltf_animation_keys

namespace {

using gltf_animation_keys::AnimatedProperty;
using gltf_animation_keys::KeyInterpolation;
using gltf_animation_keys::PropertyTrack;

// How much a node's global linear part may stray from a rotation times a uniform scale: each entry
// of its Gram matrix over the squared scale, against the identity's.
constexpr double kUniformScaleTolerance = 1e-6;

// glTF's y-up axes to the z-up object frame (C) as a matrix: its columns, where glTF's x, y, z go.
const glm::dmat3 kGltfToObject(gltf::to_object_frame({1, 0, 0}), gltf::to_object_frame({0, 1, 0}),
                               gltf::to_object_frame({0, 0, 1}));

KeyInterpolation interpolation_named(const std::string& name) {
  if (name == "STEP") return KeyInterpolation::Step;
  if (name == "CUBICSPLINE") return KeyInterpolation::CubicSpline;
  return KeyInterpolation::Linear;  // gltf_document.cpp let no other name through
}

glm::dquat quaternion_at(const std::vector<float>& values, size_t element) {
  const float* q = &values[4 * element];  // glTF: x, y, z, w
  return glm::dquat(q[3], q[0], q[1], q[2]);
}

glm::dvec4 vector_at(const PropertyTrack& track, size_t element) {
  glm::dvec4 v(0.0);
  for (size_t c = 0; c < track.components; ++c) v[int(c)] = track.values[track.components * element + c];
  return v;
}

// glTF's slerp: the short way round (the second key negated when the two disagree in sign).
glm::dquat slerp_short_way(const glm::dquat& from, glm::dquat to, double s) {
  double cosine = glm::dot(from, to);
  if (cosine < 0) {
    to = -to;
    cosine = -cosine;
  }
  // Within ~3e-6 rad of each other there is no angle to divide by; nlerp is exact to ~1e-17 there.
  if (cosine > 1 - 1e-12) return glm::normalize(from + (to - from) * s);
  const double angle = std::acos(cosine);
  return (from * std::sin((1 - s) * angle) + to * std::sin(s * angle)) / std::sin(angle);
}

// The key interval of t: the largest k with times[k] <= t (t inside the keys' range).
size_t key_before(const std::vector<float>& times, double t) {
  const auto after = std::upper_bound(times.begin(), times.end(), t, [](double v, float key) { return v < double(key); });
  return size_t(after - times.begin()) - 1;
}

// A track's value at t, as a 4-vector (x, y, z[, w]); rotations unit, in glTF's x, y, z, w order.
glm::dvec4 sample_track(const PropertyTrack& track, double t, const std::filesystem::path& path) {
  const std::vector<float>& times = *track.times;
  const bool cubic = track.interpolation == KeyInterpolation::CubicSpline;
  const size_t stride = cubic ? 3 : 1, offset = cubic ? 1 : 0;  // a CUBICSPLINE key's value is its middle element
  const bool rotation = track.property == AnimatedProperty::Rotation;
  auto key_value = [&](size_t k) {
    glm::dvec4 v = vector_at(track, stride * k + offset);
    return rotation ? v / glm::length(v) : v;  // read_track refused zero lengths
  };
  if (!(t > double(times.front()))) return key_value(0);  // before the first key (and at it)
  if (t >= double(times.back())) return key_value(times.size() - 1);
  const size_t k = key_before(times, t);
  const double t0 = times[k], span = double(times[k + 1]) - t0, s = (t - t0) / span;
  if (track.interpolation == KeyInterpolation::Step) return key_value(k);
  if (track.interpolation == KeyInterpolation::Linear) {
    if (!rotation) return glm::mix(key_value(k), key_value(k + 1), s);
    const glm::dvec4 a = key_value(k), b = key_value(k + 1);
    const glm::dquat q = slerp_short_way(glm::dquat(a.w, a.x, a.y, a.z), glm::dquat(b.w, b.x, b.y, b.z), s);
    return {q.x, q.y, q.z, q.w};
  }
  // CUBICSPLINE: Hermite between the two values, the tangents scaled by the interval.
  const double s2 = s * s, s3 = s2 * s;
  const glm::dvec4 v = (2 * s3 - 3 * s2 + 1) * vector_at(track, 3 * k + 1) +
                       span * (s3 - 2 * s2 + s) * vector_at(track, 3 * k + 2) +
                       (-2 * s3 + 3 * s2) * vector_at(track, 3 * (k + 1) + 1) +
                       span * (s3 - s2) * vector_at(track, 3 * (k + 1));
  if (!rotation) return v;
  const double length = glm::length(v);
  if (!(length > 0) || !std::isfinite(length))
    gltf::fail(path, fmt::format("{}: the rotation at t = {} s has length {}, not a rotation", track.where, t, length));
  return v / length;
}

// Reads the chosen animation's samplers and channels: every accessor read once, within the
// element budget, each key checked.
class AnimationReader {
 public:
  AnimationReader(const tinygltf::Model& model, const std::filesystem::path& path, int animation)
      : model_(model), path_(path), reader_(model, path), animation_(animation),
        label_(animation_label(model, animation)) {}

  struct Result {
    double duration_s = 0;
    std::vector<PropertyTrack> tracks;
    std::vector<std::array<int, 3>> node_tracks;  // per node: per property, the track or -1
  };

  Result read() {
    Result out;
    out.node_tracks.assign(model_.nodes.size(), {-1, -1, -1});
    const tinygltf::Animation& animation = model_.animations[size_t(animation_)];
    for (size_t s = 0; s < animation.samplers.size(); ++s)
      out.duration_s = std::max(out.duration_s, double(input_times(int(s))->back()));
    std::map<std::pair<int, bool>, int> track_of;  // (sampler, rotation?): the track read for it
    for (size_t c = 0; c < animation.channels.size(); ++c) {
      const tinygltf::AnimationChannel& channel = animation.channels[c];
      if (channel.target_path == "weights") continue;  // morph targets: not read
      const AnimatedProperty property = channel.target_path == "translation" ? AnimatedProperty::Translation
                                        : channel.target_path == "rotation"  ? AnimatedProperty::Rotation
                                                                             : AnimatedProperty::Scale;
      if (channel.target_node < 0 || size_t(channel.target_node) >= model_.nodes.size() || channel.sampler < 0 ||
          size_t(channel.sampler) >= animation.samplers.size())  // gltf_document.cpp checked both
        fail(fmt::format("{} channel {}: its node {} or sampler {} does not exist", label_, c, channel.target_node,
                         channel.sampler));
      int& slot = out.node_tracks[size_t(channel.target_node)][size_t(property)];
      check_target(int(c), channel, slot, animation.channels);
      const auto key = std::make_pair(channel.sampler, property == AnimatedProperty::Rotation);
      auto found = track_of.find(key);
      if (found == track_of.end()) {
        out.tracks.push_back(read_track(int(c), channel.sampler, property));
        found = track_of.emplace(key, int(out.tracks.size() - 1)).first;
      }
      slot = found->second;
    }
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { gltf::fail(path_, what); }

  static std::string animation_label(const tinygltf::Model& model, int animation) {
    const std::string& name = model.animations[size_t(animation)].name;
    return name.empty() ? fmt::format("animation {}", animation) : fmt::format("animation {} (\"{}\")", animation, name);
  }

  // One property of one node per animation (glTF), and never a node with a matrix.
  void check_target(int c, const tinygltf::AnimationChannel& channel, int slot,
                    const std::vector<tinygltf::AnimationChannel>& channels) const {
    const int node = channel.target_node;
    if (model_.nodes[size_t(node)].matrix.size() == 16)
      fail(fmt::format("{} channel {}: its target, {}, has a matrix; glTF animates only nodes with translation, "
                       "rotation and scale",
                       label_, c, gltf::node_label(model_, node)));
    if (slot >= 0)
      for (int other = 0; other < c; ++other)
        if (channels[size_t(other)].target_node == node && channels[size_t(other)].target_path == channel.target_path)
          fail(fmt::format("{} channel {}: {}'s {} is the target of channel {} already (glTF: one channel a target)",
                           label_, c, gltf::node_label(model_, node), channel.target_path, other));
  }

  // The budget of elements read, before reading `count` more.
  void spend(size_t count, const std::string& where) {
    if (__builtin_add_overflow(elements_read_, count, &elements_read_) || elements_read_ > kMaxGltfAnimationElementsRead)
      fail(fmt::format("{}: reading the animation reads more than {} accessor elements, the limit", where,
                       kMaxGltfAnimationElementsRead));
  }

  // A sampler's input: FLOAT SCALAR times, at least one, >= 0, strictly increasing (each
  // accessor read once, however many samplers share it).
  std::shared_ptr<const std::vector<float>> input_times(int sampler) {
    const int index = model_.animations[size_t(animation_)].samplers[size_t(sampler)].input;
    if (auto cached = inputs_.find(index); cached != inputs_.end()) return cached->second;
    const std::string where = fmt::format("{} sampler {} input", label_, sampler);
    const tinygltf::Accessor& accessor = reader_.accessor(index, where);
    if (accessor.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || accessor.type != TINYGLTF_TYPE_SCALAR)
      fail(fmt::format("{}: accessor {} must be SCALAR of FLOAT (times in seconds)", where, index));
    const gltf::AccessorSpan span = reader_.span(accessor, index, where, 4, kMaxGltfAnimationKeys, "keys");
    if (span.count == 0) fail(fmt::format("{}: accessor {} has no keys", where, index));
    spend(span.count, where);
    auto times = std::make_shared<std::vector<float>>(reader_.read_floats(span, accessor, index, where, 1));
    for (size_t k = 0; k < times->size(); ++k) {
      if ((*times)[k] < 0) fail(fmt::format("{}: accessor {} element {} is {} s, before 0", where, index, k, (*times)[k]));
      if (k > 0 && !((*times)[k] > (*times)[k - 1]))
        fail(fmt::format("{}: accessor {} element {} is {} s, not after element {} ({} s): times must increase", where,
                         index, k, (*times)[k], k - 1, (*times)[k - 1]));
    }
    inputs_.emplace(index, times);
    return times;
  }

  PropertyTrack read_track(int c, int sampler_index, AnimatedProperty property) {
    const tinygltf::AnimationSampler& sampler = model_.animations[size_t(animation_)].samplers[size_t(sampler_index)];
    PropertyTrack track;
    track.property = property;
    track.interpolation = interpolation_named(sampler.interpolation);
    track.times = input_times(sampler_index);
    track.where = fmt::format("{} channel {} (sampler {})", label_, c, sampler_index);
    const std::string where = track.where + " output";
    const bool rotation = property == AnimatedProperty::Rotation;
    track.components = rotation ? 4 : 3;
    const tinygltf::Accessor& accessor = reader_.accessor(sampler.output, where);
    check_output_type(accessor, sampler.output, where, rotation);
    const size_t per_key = track.interpolation == KeyInterpolation::CubicSpline ? 3 : 1;
    const gltf::AccessorSpan span = reader_.span(accessor, sampler.output, where,
                                                 track.components * gltf::AccessorReader::component_bytes(accessor.componentType),
                                                 per_key * kMaxGltfAnimationKeys, "values (three a key for CUBICSPLINE)");
    if (span.count != per_key * track.times->size())
      fail(fmt::format("{}: accessor {} has {} elements, but the input's {} keys need {}", where, sampler.output,
                       span.count, track.times->size(), per_key * track.times->size()));
    spend(span.count, where);
    track.values = reader_.read_floats(span, accessor, sampler.output, where, track.components);
    if (rotation)
      for (size_t k = 0; k < track.times->size(); ++k)  // the values, not the tangents, must be rotations
        if (glm::length(quaternion_at(track.values, per_key * k + (per_key - 1) / 2)) == 0)
          fail(fmt::format("{}: accessor {}: the rotation of key {} has zero length", where, sampler.output, k));
    return track;
  }

  // Translation and scale: FLOAT VEC3; rotation: VEC4 of FLOAT or of normalised integers (glTF).
  void check_output_type(const tinygltf::Accessor& accessor, int index, const std::string& where, bool rotation) const {
    if (!rotation) {
      if (accessor.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || accessor.type != TINYGLTF_TYPE_VEC3)
        fail(fmt::format("{}: accessor {} must be VEC3 of FLOAT", where, index));
      return;
    }
    const bool is_float = accessor.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
    if (accessor.type != TINYGLTF_TYPE_VEC4 || gltf::AccessorReader::component_bytes(accessor.componentType) == 0 ||
        is_float == accessor.normalized)
      fail(fmt::format("{}: accessor {} must be VEC4 of FLOAT, or of normalized BYTE, UNSIGNED_BYTE, SHORT or "
                       "UNSIGNED_SHORT",
                       where, index));
  }

  const tinygltf::Model& model_;
  const std::filesystem::path& path_;
  gltf::AccessorReader reader_;
  int animation_;
  std::string label_;
  uint64_t elements_read_ = 0;
  std::map<int, std::shared_ptr<const std::vector<float>>> inputs_;  // by accessor
};

// Why the Gram matrix (L^T L of a linear part L) is not a uniform scale's (scale_squared times the
// identity, within kUniformScaleTolerance an entry, relative); nullopt when it is.
std::optional<std::string> not_uniform_scale(const glm::dmat3& gram, double scale_squared) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (std::abs(gram[i][j] / scale_squared - (i == j ? 1.0 : 0.0)) > kUniformScaleTolerance)
        return fmt::format("its axes are {:.9g}, {:.9g} and {:.9g} long, the cosines between them {:.3g}, {:.3g} and "
                           "{:.3g} (tolerance {} relative)",
                           std::sqrt(gram[0][0]), std::sqrt(gram[1][1]), std::sqrt(gram[2][2]),
                           gram[0][1] / std::sqrt(gram[0][0] * gram[1][1]), gram[0][2] / std::sqrt(gram[0][0] * gram[2][2]),
                           gram[1][2] / std::sqrt(gram[1][1] * gram[2][2]), kUniformScaleTolerance);
  return std::nullopt;
}

// The animation `name` names ("": the first); -1 when the file has none and `name` is "".
int chosen_animation(const tinygltf::Model& model, const std::filesystem::path& path, std::string_view name) {
  if (name.empty()) return model.animations.empty() ? -1 : 0;
  int found = -1;
  std::vector<std::string> names;
  for (size_t a = 0; a < model.animations.size(); ++a) {
    names.push_back(fmt::format("\"{}\"", model.animations[a].name));
    if (model.animations[a].name != name) continue;
    if (found >= 0) gltf::fail(path, fmt::format("animations {} and {} are both named \"{}\"", found, a, name));
    found = int(a);
  }
  if (found < 0) {
    if (names.size() > 10) names.resize(10), names.push_back("...");
    gltf::fail(path, fmt::format("no animation is named \"{}\" (the file's: {})", name,
                                 names.empty() ? std::string("none") : fmt::format("{}", fmt::join(names, ", "))));
  }
  return found;
}

}  // namespace

struct GltfAnimation::Impl {
  using PropertyTrack = gltf_animation_keys::PropertyTrack;
  std::filesystem::path path;
  tinygltf::Model model;  // its nodes and lights (the buffers are let go once the keys are read)
  gltf::NodeTree tree;
  std::string name;
  double duration_s = 0;
  std::vector<PropertyTrack> tracks;
  std::vector<std::array<int, 3>> node_tracks;  // per node: per property, the track or -1
  std::vector<bool> moves;                      // per node: it or an ancestor has a track
  // The scene's nodes with a light and their ancestors, parents first (the loader's order): each
  // with its parent's place in this list (-1: a root) and whether it holds a light.
  struct LightWalkStep {
    int node;
    int parent_step;
    bool light;
  };
  std::vector<LightWalkStep> light_walk;

  void plan_light_walk() {
    const auto has_light = [&](int node) { return model.nodes[size_t(node)].extensions.count("KHR_lights_punctual") > 0; };
    std::vector<bool> needed(model.nodes.size(), false);
    for (int node : tree.order)  // each node marked once: linear in the nodes
      if (has_light(node))
        for (int n = node; n >= 0 && !needed[size_t(n)]; n = tree.parent[size_t(n)]) needed[size_t(n)] = true;
    std::vector<int> step_of(model.nodes.size(), -1);
    for (int node : tree.order) {
      if (!needed[size_t(node)]) continue;
      const int parent = tree.parent[size_t(node)];
      step_of[size_t(node)] = int(light_walk.size());
      light_walk.push_back({node, parent >= 0 ? step_of[size_t(parent)] : -1, has_light(node)});
    }
  }

  void check_node(int node) const {
    if (node < 0 || size_t(node) >= model.nodes.size() || !tree.in_scene[size_t(node)])
      gltf::fail(path, fmt::format("node {} is not a node of the scene ({} nodes in the file)", node, model.nodes.size()));
  }

  glm::dmat4 local_at(int node, double t) const {
    const std::array<int, 3>& own = node_tracks[size_t(node)];
    if (own[0] < 0 && own[1] < 0 && own[2] < 0) return gltf::rest_transform(model, path, node);
    gltf::NodeTrs trs = gltf::rest_trs(model, path, node);
    if (own[0] >= 0) trs.translation = glm::dvec3(sample_track(tracks[size_t(own[0])], t, path));
    if (own[1] >= 0) {
      const glm::dvec4 q = sample_track(tracks[size_t(own[1])], t, path);
      trs.rotation = glm::dquat(q.w, q.x, q.y, q.z);
    }
    if (own[2] >= 0) trs.scale = glm::dvec3(sample_track(tracks[size_t(own[2])], t, path));
    return gltf::trs_transform(trs.translation, trs.rotation, trs.scale);
  }

  // glTF's global transform G(t): the product of the local transforms from the root down.
  glm::dmat4 global_at(int node, double t) const {
    if (std::isnan(t)) throw std::invalid_argument(fmt::format("{}: an animation time that is not a number", path.string()));
    std::vector<int> chain;
    for (int n = node; n >= 0; n = tree.parent[size_t(n)]) chain.push_back(n);
    glm::dmat4 global(1.0);
    for (auto n = chain.rbegin(); n != chain.rend(); ++n) global *= local_at(*n, t);
    return global;
  }
};

GltfAnimation::GltfAnimation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GltfAnimation::GltfAnimation(GltfAnimation&&) noexcept = default;
GltfAnimation& GltfAnimation::operator=(GltfAnimation&&) noexcept = default;
GltfAnimation::~GltfAnimation() = default;

GltfAnimation GltfAnimation::load(const std::filesystem::path& path, std::string_view animation) {
  return gltf::as_asset_errors(path, [&] {
    auto impl = std::make_unique<Impl>();
    impl->path = path;
    impl->model = gltf::load_checked_model(path);
    const tinygltf::Model& model = impl->model;
    impl->tree = gltf::scene_node_tree(model, path);
    for (int node : impl->tree.order) gltf::rest_transform(model, path, node);  // finite, as the loader asks
    impl->node_tracks.assign(model.nodes.size(), {-1, -1, -1});
    if (const int chosen = chosen_animation(model, path, animation); chosen >= 0) {
      AnimationReader::Result read = AnimationReader(model, path, chosen).read();
      impl->name = model.animations[size_t(chosen)].name;
      impl->duration_s = read.duration_s;
      impl->tracks = std::move(read.tracks);
      impl->node_tracks = std::move(read.node_tracks);
    }
    impl->moves.assign(model.nodes.size(), false);
    for (int node : impl->tree.order) {  // parents first
      const std::array<int, 3>& own = impl->node_tracks[size_t(node)];
      const int parent = impl->tree.parent[size_t(node)];
      impl->moves[size_t(node)] = own[0] >= 0 || own[1] >= 0 || own[2] >= 0 || (parent >= 0 && impl->moves[size_t(parent)]);
    }
    impl->plan_light_walk();
    impl->model.buffers.clear();  // the keys are read: let the file's bytes go
    impl->model.bufferViews.clear();
    impl->model.accessors.clear();
    impl->model.meshes.clear();
    impl->model.animations.clear();
    return GltfAnimation(std::move(impl));
  });
}

const std::string& GltfAnimation::name() const { return impl_->name; }

double GltfAnimation::duration_s() const { return impl_->duration_s; }

std::optional<int> GltfAnimation::find_node(std::string_view name) const {
  if (name.empty()) return std::nullopt;
  return gltf::find_named_node(impl_->model, impl_->tree, impl_->path, name);
}

bool GltfAnimation::moves(int node) const {
  impl_->check_node(node);
  return impl_->moves[size_t(node)];
}

ScaledPose GltfAnimation::node_pose_at(int node, double t_s) const {
  impl_->check_node(node);
  const glm::dmat4 global = impl_->global_at(node, t_s);
  // N = C G C^-1: the linear part turned both ways, the translation turned.
  const glm::dmat3 linear = kGltfToObject * glm::dmat3(global) * glm::transpose(kGltfToObject);
  const glm::dvec3 translation = kGltfToObject * glm::dvec3(global[3]);
  const glm::dmat3 gram = glm::transpose(linear) * linear;
  const double scale_squared = (gram[0][0] + gram[1][1] + gram[2][2]) / 3;
  const auto not_rigid = [&](const std::string& why) {
    gltf::fail(impl_->path, fmt::format("{}: its global transform at t = {} s is not a rotation, a translation and a "
                                        "uniform scale (on it or an ancestor): {}",
                                        gltf::node_label(impl_->model, node), t_s, why));
  };
  if (!std::isfinite(scale_squared) || !std::isfinite(translation.x + translation.y + translation.z))
    not_rigid("it is not finite");
  const Vec3 t{translation.x, translation.y, translation.z};
  if (scale_squared == 0) return {SE3(identity3(), t), 0.0};  // a zero scale: any rotation places it alike
  if (const std::optional<std::string> why = not_uniform_scale(gram, scale_squared)) not_rigid(*why);
  if (glm::determinant(linear) < 0) not_rigid("it mirrors (a negative determinant)");
  const double scale = std::sqrt(scale_squared);
  Mat3 rotation{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) rotation[size_t(r)][size_t(c)] = linear[c][r] / scale;  // glm: [column][row]
  return {SE3(rotation, t).normalized(), scale};
}

std::vector<GltfLight> GltfAnimation::lights_at(double t_s) const {
  if (std::isnan(t_s)) throw std::invalid_argument(fmt::format("{}: an animation time that is not a number", impl_->path.string()));
  std::vector<GltfLight> lights;
  std::vector<glm::dmat4> global(impl_->light_walk.size());
  for (size_t i = 0; i < impl_->light_walk.size(); ++i) {
    const Impl::LightWalkStep& step = impl_->light_walk[i];
    global[i] = (step.parent_step >= 0 ? global[size_t(step.parent_step)] : glm::dmat4(1.0)) * impl_->local_at(step.node, t_s);
    if (!step.light) continue;
    if (std::optional<GltfLight> light = gltf::placed_light(impl_->model, impl_->path, step.node, global[i]))
      lights.push_back(std::move(*light));
  }
  return lights;
}

}  // namespace arpipe
