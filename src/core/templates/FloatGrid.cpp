// The one compiled copy of openvdb::FloatGrid and its tree (include/strata/core/GridTypes.hpp says
// why). One file per type, so that a parallel build compiles them side by side.
#include "strata/core/GridTypes.hpp"

namespace openvdb {
OPENVDB_USE_VERSION_NAMESPACE
namespace OPENVDB_VERSION_NAME {

template class tree::Tree<FloatTree::RootNodeType>;
template class Grid<FloatTree>;

}  // namespace OPENVDB_VERSION_NAME
}  // namespace openvdb
