// The one compiled copy of the grid of strata::core::SparseBoolTree and its tree
// (include/strata/core/GridTypes.hpp says why).
#include "strata/core/GridTypes.hpp"

namespace openvdb {
OPENVDB_USE_VERSION_NAMESPACE
namespace OPENVDB_VERSION_NAME {

template class tree::Tree<strata::core::SparseBoolTree::RootNodeType>;
template class Grid<strata::core::SparseBoolTree>;

}  // namespace OPENVDB_VERSION_NAME
}  // namespace openvdb
