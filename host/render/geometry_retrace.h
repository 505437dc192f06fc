// geometry_retrace.h — the GPU half of a geometry edit [IVR §3.3]: which pixels the changed boxes
// can change (dirty.comp, optionally narrowed by probes that replay those pixels' rays,
// lib/probe.glsl), their sums cleared, and every sample so far traced again over them alone; and
// whether the rays the frame keeps (lobe hits by BVH texel) still name the scene's triangles.
//
// One of ObscuranceRenderer's jobs, kept apart: it owns the dirty pass, the lights' bounds that
// pass reads and the kept rays' validity; it drives the renderer's sample loop through
// SampleRecorder, so the retraced pixels get exactly the passes a full render gives them.
#pragma once
#include <cstdint>
#include <vector>

#include "bvh/bvh.h"
#include "gpu/command_stream.h"
#include "gpu/context.h"
#include "gpu/timestamps.h"
#include "render/frame/obscurance_frame.h"
#include "render/passes/dirty_pass.h"
#include "render/scene_data/light_set.h"
#include "core/names.h"
#include "scene/scene.h"

namespace obscura::render {

// The dirty test of a geometry edit (ObscuranceSettings::dirtyTest).
enum class DirtyTest { Auto, Bounds, Probe };
inline constexpr NameTable<DirtyTest, 3> kDirtyTestNames{
    {{"auto", DirtyTest::Auto}, {"probe", DirtyTest::Probe}, {"bounds", DirtyTest::Bounds}}};

// How a sample's passes run: over every pixel (a render), over the dirty list (a geometry edit's
// retrace), or probing the dirty list's candidates (the primary pass remakes their G-buffer, the
// shading passes test their rays against the changed boxes: lib/probe.glsl).
enum class SampleMode { Render, Retrace, Probe };

// The renderer's sample loop as a retrace drives it: sample `sample`'s passes in `mode`;
// `tracePrimary` false: the G-buffer holds the sample already.
class SampleRecorder {
public:
  virtual void recordSample(const vk::raii::CommandBuffer& cmd, std::uint32_t sample, SampleMode mode,
                            bool tracePrimary) = 0;

protected:
  ~SampleRecorder() = default;
};

class GeometryRetrace {
public:
  GeometryRetrace(const gpu::Context& context, const FrameLayout& layout, const bvh::Bvh& bvh);

  // The lights whose shafts the dirty test follows (after every change of the light set), through
  // `uploads`; true when their buffer was made anew (bind again).
  bool setLights(const gpu::Context& context, const LightSet& lights, gpu::UploadBatch& uploads);
  void bind(std::uint32_t band, const ObscuranceFrame& frame) { dirty_.bind(band, frame, lightBounds_); }

  // The scene's BVH is now `bvh`: a rebuild lays the triangles out anew, and the kept lobe hits
  // (which name triangles by their texel in the layout) then name other triangles; a refit keeps them.
  void useBvh(const bvh::Bvh& bvh);
  // The samples to come write the kept rays anew (a reset).
  void keptRaysRenderedAnew() { keptRaysValid_ = true; }
  // Whether the kept rays are the current scene's (a replay may follow them).
  bool keptRaysValid() const { return keptRaysValid_; }

  // What a retrace reads of the renderer's frame.
  struct Frame {
    gpu::CommandStream& stream;
    gpu::Timestamps& timestamps;
    SampleRecorder& recorder;
    const ObscuranceFrame& buffers;
    gpu::GpuCamera camera;
    std::uint32_t lights = 0;
    std::uint32_t samples = 0;        // samples so far: each is traced again
    std::uint32_t gbufferSample = ~0u; // the sample whose primary hits the G-buffer holds (~0u: none)
    float dMax = 0.0f;
    float changedBoxPadding = 0.0f;   // render/light_reach_model.h
    bool specular = false;            // the frame has specular paths
  };
  // The edit.
  struct Edit {
    const std::vector<scene::Bounds>& changed; // world boxes of what changed (old and new places)
    bool everyPixel = false;                   // anything may change anywhere (emitters moved, the
                                               // sky, secondary reflectors)
    std::uint32_t tracedLight = gpu::kInvalidIndex; // a new light traced at every pixel already:
                                                    // its shafts are not tested
    bool probe = false;                        // replay the candidates' rays (probing())
  };
  struct Result {
    std::uint64_t pixels = 0; // retraced, for every sample
    bool probed = false;      // the probes remade the candidates' G-buffer
  };
  // Marks, clears and retraces the pixels `edit` can change, every sample so far.
  Result retrace(const Frame& frame, const Edit& edit);

  // Whether a retrace probes: Probe always, Bounds never, Auto where rays may pass anywhere
  // (`unbounded`: specular paths, obscurance rays traced on past dMax (EscapeModel); a path that
  // left the scene bounds nothing, so the bounds keep most of those pixels) or the frame keeps
  // every sample's rays (the probes then draw no light sample: cheaper than the retrace they
  // save). Never after a new light changed how lights are chosen (the replayed rays would not be
  // those traced), nor before a sample.
  static bool probing(DirtyTest test, bool unbounded, bool keptEverySample);

private:
  // Every sample so far replayed over the candidates dirty.comp listed, each ray tested against
  // the changed boxes (lib/probe.glsl).
  void probeCandidates(const Frame& frame);

  DirtyPass dirty_;
  gpu::Buffer lightBounds_; // for dirty.comp
  bool keptRaysValid_ = true;
  std::vector<std::uint32_t> bvhOrder_; // the layout the kept hits refer to: triangle order...
  std::size_t bvhNodes_ = 0;            // ...after this many nodes
};

} // namespace obscura::render
