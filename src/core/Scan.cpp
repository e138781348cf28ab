#include "strata/core/Scan.hpp"

#include <stdexcept>

#include "strata/core/Error.hpp"

namespace strata::core {

void Scan::Validate() const {
    const std::string where = source.empty() ? std::string("scan") : source;
    const size_t n = points.size();
    if (!labels.empty() && labels.size() != n) {
        throw InvalidArgumentError(where + ": " + std::to_string(labels.size()) + " labels for " +
                                   std::to_string(n) + " points");
    }
    if (!instances.empty() && instances.size() != n) {
        throw InvalidArgumentError(where + ": " + std::to_string(instances.size()) +
                                   " instance ids for " + std::to_string(n) + " points");
    }
    if (!intensity.empty() && intensity.size() != n) {
        throw InvalidArgumentError(where + ": " + std::to_string(intensity.size()) +
                                   " intensities for " + std::to_string(n) + " points");
    }
    if (!T_world_sensor.matrix().allFinite()) {
        throw InvalidArgumentError(where + ": the sensor pose is not finite");
    }
}

}  // namespace strata::core
