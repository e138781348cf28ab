// The one compiled copy of openvdb::Int32Grid and its tree (include/strata/core/GridTypes.hpp says
// why). One file per type, so that a parallel build compiles them side by side.
#include "strata/core/GridTypes.hpp"

namespace openvdb {
OPENVDB_USE_VERSION_NAMESPACE
namespace OPENVDB_VERSION_NAME {

template class tree::Tree<Int32Tree::RootNodeType>;
template class Grid<Int32Tree>;

}  // namespace OPENVDB_VERSION_NAME
}  // namespace openvdb
