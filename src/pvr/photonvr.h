#pragma once
// photonvr's public API, for applications (find_package(photonvr); target photonvr::photonvr):
//
//   pvr::Scene scene = pvr::loadScene("sponza.gltf");   // or builtinScene, or addMesh + finalize
//   pvr::Renderer renderer(scene);                        // CUDA when a GPU is present, else the CPU
//   renderer.rig().width = 1440, renderer.rig().height = 1600;
//   renderer.options().photonsX = renderer.options().photonsY = 512;
//   pvr::FrameResult frame = renderer.renderFrame(headPose, gaze);
//   // frame.eyes[0].image, frame.eyes[1].image: linear RGB; frame.timings: per stage
//
// Everything throws pvr::Error (OptionError for options out of range) with a one-line message.
#include "pvr/foveation/mask.h"
#include "pvr/image/image_io.h"
#include "pvr/pipeline/frame_renderer.h"
#include "pvr/render/renderer.h"
#include "pvr/scene/scene.h"
