// The process's one Embree device, for the files that call Embree directly
// (ray_scene.cpp, scene_bvh.cpp); nothing else includes Embree.
#pragma once

#include <embree3/rtcore.h>

namespace radiosity {

// Created on first use, never released: creating one costs milliseconds.
// Throws std::runtime_error if Embree cannot start.
RTCDevice shared_embree_device();

}  // namespace radiosity
