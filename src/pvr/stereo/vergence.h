#pragma once
// Vergence: both eyes fixate one surface point. The left eye's gaze is given; the right eye's
// follows from what the left eye's gaze ray meets.
#include "pvr/camera/stereo_rig.h"

namespace pvr {

// The right eye's gaze (image fractions, clamped to the image) that fixates the point at inverse
// depth *leftInverseDepthAtGaze (0: at infinity) on the ray through the centre of the left eye's
// gaze pixel for `leftGaze`; the left eye's image position if that is null (the left eye not
// rendered) or the point is behind the right eye.
void vergeRightGaze(const StereoRig& rig, const float leftGaze[2], const float* leftInverseDepthAtGaze,
                    float rightGaze[2]);

// The pixel of an eye of width x height that a gaze (image fractions) falls on.
void gazePixelOf(const float gaze[2], int width, int height, int& x, int& y);

}  // namespace pvr
