// queue_append.glsl — appending to a queue of indices with its indirect dispatch in the header
// (kQueueHeader words: groups x, y, z, then the count; the host resets it to (0, 1, 1, 0)).
//
// The lanes of a SIMD group that append take consecutive slots in lane order (neighbours stay
// neighbours), with one atomic on the count and one on the groups per group instead of per lane:
// on lavapipe every lane's atomic on the one counter is a serialised memory operation, and a pass
// that appends most of a frame's pixels (the glossy queue, a geometry edit's candidates) spent a
// large share of its time on them.
#ifndef OBSCURA_QUEUE_APPEND_GLSL
#define OBSCURA_QUEUE_APPEND_GLSL

#extension GL_KHR_shader_subgroup_ballot : require

// Appends `item` to the queue in `buffer` whose header starts at word `base`; every active lane
// appends. Evaluates to nothing; `buffer` is the name of a uint[] in a storage block.
#define OBS_QUEUE_APPEND(buffer, base, item)                                                       \
  {                                                                                                \
    const uvec4 obsLanes = subgroupBallot(true);                                                   \
    const uint obsCount = subgroupBallotBitCount(obsLanes);                                        \
    uint obsFirst = 0u;                                                                            \
    if (subgroupElect()) {                                                                         \
      obsFirst = atomicAdd(buffer[(base) + kQueueCount], obsCount);                                \
      atomicMax(buffer[(base) + kQueueGroupsX], (obsFirst + obsCount - 1u) / kWorkgroupSize1D + 1u); \
    }                                                                                              \
    buffer[(base) + kQueueHeader + subgroupBroadcastFirst(obsFirst) + subgroupBallotExclusiveBitCount(obsLanes)] = (item); \
  }

#endif
