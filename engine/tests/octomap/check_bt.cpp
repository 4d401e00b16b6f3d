// Checker for uavex's OctoMap .bt writer, built against the real OctoMap library
// (Debian liboctomap-dev) by run.sh and driven by engine/tests/octomap_bt.rs.
//
//   check_bt read FILE.bt  < points   loads FILE.bt with octomap::OcTree::readBinary and prints
//                                     "res R", "size N", "leaves N", one
//                                     "leaf DEPTH OCCUPIED MINX MINY MINZ" per leaf (min corner
//                                     as map voxel keys), then one state per query point
//                                     "x y z" read from stdin: occupied, free or unknown.
//   check_bt write FILE.bt RES < voxels
//                                     builds an OcTree from lines "kx ky kz occupied(0|1)"
//                                     (map voxel keys) with updateNode and saves it with
//                                     writeBinary, as a reference for byte comparison.
#include <octomap/OcTree.h>
#include <octomap/octomap.h>

#include <cmath>
#include <iostream>
#include <string>

namespace {

int read_mode(const std::string& path) {
  octomap::OcTree tree(0.1);
  if (!tree.readBinary(path)) {
    std::cerr << "readBinary failed for " << path << "\n";
    return 1;
  }
  const double res = tree.getResolution();
  std::cout.precision(17);
  std::cout << "res " << res << "\n";
  std::cout << "size " << tree.size() << "\n";
  std::cout << "leaves " << tree.getNumLeafNodes() << "\n";
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    const octomap::point3d c = it.getCoordinate();
    const double half = it.getSize() / 2.0;
    std::cout << "leaf " << it.getDepth() << " " << (tree.isNodeOccupied(*it) ? 1 : 0);
    for (int a = 0; a < 3; ++a) {
      std::cout << " " << static_cast<long>(std::lround((c(a) - half) / res));
    }
    std::cout << "\n";
  }
  double x, y, z;
  while (std::cin >> x >> y >> z) {
    const octomap::OcTreeNode* node = tree.search(x, y, z);
    const char* state = node == nullptr ? "unknown" : (tree.isNodeOccupied(node) ? "occupied" : "free");
    std::cout << "query " << state << "\n";
  }
  return 0;
}

int write_mode(const std::string& path, double res) {
  octomap::OcTree tree(res);
  long kx, ky, kz;
  int occupied;
  while (std::cin >> kx >> ky >> kz >> occupied) {
    const octomap::OcTreeKey key(kx + 32768, ky + 32768, kz + 32768);
    tree.updateNode(key, occupied != 0, false);
  }
  if (!tree.writeBinary(path)) {
    std::cerr << "writeBinary failed for " << path << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "read" && argc == 3) return read_mode(argv[2]);
  if (mode == "write" && argc == 4) return write_mode(argv[2], std::stod(argv[3]));
  std::cerr << "usage: check_bt read FILE.bt < points | check_bt write FILE.bt RES < voxels\n";
  return 2;
}
