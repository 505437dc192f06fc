#include "render/geometry_retrace.h"

#include <algorithm>

#include "render/aovs.h"

namespace obscura::render {

GeometryRetrace::GeometryRetrace(const gpu::Context& context, const FrameLayout& layout, const bvh::Bvh& bvh)
    : dirty_(context, layout.bandCount()), bvhOrder_(bvh.order), bvhNodes_(bvh.nodes.size()) {}

bool GeometryRetrace::setLights(const gpu::Context& context, const LightSet& lights, gpu::UploadBatch& uploads) {
  return gpu::refillArray(context, uploads, lightBounds_, lightBounds(lights), "dirty.light_bounds");
}

void GeometryRetrace::useBvh(const bvh::Bvh& bvh) {
  if (bvh.nodes.size() == bvhNodes_ && bvh.order == bvhOrder_) return; // a refit
  keptRaysValid_ = false;
  bvhOrder_ = bvh.order;
  bvhNodes_ = bvh.nodes.size();
}

bool GeometryRetrace::probing(DirtyTest test, bool unbounded, bool keptEverySample) {
  return test == DirtyTest::Probe || (test == DirtyTest::Auto && (unbounded || keptEverySample));
}

GeometryRetrace::Result GeometryRetrace::retrace(const Frame& frame, const Edit& edit) {
  const FrameLayout& layout = frame.buffers.layout();
  // The frame's status words count the pixels dirty.comp marks.
  const auto markedPixels = [&] { return frame.buffers.statusWords()[gpu::kStatusDirtyPixels]; };
  const std::uint32_t bands = layout.bandCount();
  // Probing replays the rays the frame traced, so not after addEmitter: its new light changed how
  // lights are chosen, and the replayed rays would not be those traced.
  const bool probe = edit.probe && !edit.everyPixel && edit.tracedLight == gpu::kInvalidIndex && frame.samples > 0;
  // Each changed box grown by frame.changedBoxPadding: ray origins leave their surfaces by a few
  // hundred ulps of their coordinates (lib/ray.glsl).
  for (std::uint32_t b = 0; b < bands; ++b)
    dirty_.prepare(b, layout, frame.camera, edit.changed, frame.changedBoxPadding, frame.dMax, frame.lights,
                   edit.everyPixel, edit.tracedLight, probe);
  const auto clear = [&](const vk::raii::CommandBuffer& cmd) {
    gpu::computeBarrier(cmd);
    for (std::uint32_t b = 0; b < bands; ++b) dirty_.recordClear(cmd, b, layout, frame.lights, frame.specular);
  };
  const auto timed = [&](const auto& record) {
    frame.stream.submit([&](const vk::raii::CommandBuffer& cmd) {
      frame.timestamps.reset(cmd);
      frame.timestamps.time(cmd, "dirty", [&] { record(cmd); });
    });
    frame.timestamps.collect();
  };
  const std::uint32_t dirtyBefore = markedPixels();
  timed([&](const vk::raii::CommandBuffer& cmd) {
    for (std::uint32_t b = 0; b < bands; ++b) dirty_.record(cmd, b, layout);
    if (!probe) clear(cmd);
  });
  if (probe) {
    probeCandidates(frame);
    timed([&](const vk::raii::CommandBuffer& cmd) {
      for (std::uint32_t b = 0; b < bands; ++b) dirty_.recordList(cmd, b, layout);
      clear(cmd);
    });
  }
  const Result result{.pixels = markedPixels() - dirtyBefore, .probed = probe};
  for (std::uint32_t first = 0; result.pixels > 0 && first < frame.samples; first += kSamplesPerSubmission) {
    const std::uint32_t last = std::min(frame.samples, first + kSamplesPerSubmission);
    frame.stream.submit([&](const vk::raii::CommandBuffer& cmd) {
      frame.timestamps.reset(cmd);
      for (std::uint32_t s = first; s < last; ++s) {
        gpu::computeBarrier(cmd);
        frame.recorder.recordSample(cmd, s, SampleMode::Retrace, true);
      }
    });
    frame.timestamps.collect();
  }
  return result;
}

void GeometryRetrace::probeCandidates(const Frame& frame) {
  // Every sample in order over the candidates: the G-buffer holds sample 0 already only where the
  // frame has one sample; else each sample's primary hits are traced again (G-buffer only: the
  // candidates' camera rays miss the changed boxes, so they find what the frame's did).
  for (std::uint32_t first = 0; first < frame.samples; first += kSamplesPerSubmission) {
    const std::uint32_t last = std::min(frame.samples, first + kSamplesPerSubmission);
    frame.stream.submit([&](const vk::raii::CommandBuffer& cmd) {
      frame.timestamps.reset(cmd);
      for (std::uint32_t s = first; s < last; ++s) {
        gpu::computeBarrier(cmd);
        frame.recorder.recordSample(cmd, s, SampleMode::Probe, !(s == 0 && frame.gbufferSample == 0));
      }
    });
    frame.timestamps.collect();
  }
}

} // namespace obscura::render
