// The one compiled copy of openvdb::MaskGrid and its tree (include/strata/core/GridTypes.hpp says
// why). One file per type, so that a parallel build compiles them side by side.
#include "strata/core/GridTypes.hpp"

namespace openvdb {
OPENVDB_USE_VERSION_NAMESPACE
namespace OPENVDB_VERSION_NAME {

template class tree::Tree<MaskTree::RootNodeType>;
template class Grid<MaskTree>;

}  // namespace OPENVDB_VERSION_NAME
}  // namespace openvdb
