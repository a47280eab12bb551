#pragma once
// Which photon map a frame builds: the paper's hash grid (section 3.1) or the kd-tree it is
// compared with.
namespace pvr {

enum class PhotonMapKind : int { HashGrid = 0, KdTree = 1 };

}  // namespace pvr
