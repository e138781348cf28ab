#pragma once
// The kinds of failure the library reports (docs/architecture.md, "Errors"). Callers branch on
// the kind, never on the message; the message names the file, argument or map at fault. The
// `strata` program maps each kind to an exit code (tools/strata/Main.cpp, README "Exit codes"),
// the Python module to an exception class of the same name.

#include <stdexcept>
#include <string>

namespace strata {

/// @brief Base of every error the library throws on purpose.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// @brief A bad argument, config value or precondition of the caller (a negative voxel size, a
/// scan without points where points are required, a session that is committed already).
class InvalidArgumentError : public Error {
public:
    using Error::Error;
};

/// @brief A file whose content is malformed or of a format this build does not read: a point
/// cloud, a pose file, a scene, a tile or catalog that is corrupt, or a map of a newer format.
class FormatError : public Error {
public:
    using Error::Error;
};

/// @brief Something named does not exist: a map directory, a session, an input file.
class NotFoundError : public Error {
public:
    using Error::Error;
};

/// @brief Another process holds the map's writer lock; retrying later can succeed.
class MapLockedError : public Error {
public:
    using Error::Error;
};

/// @brief The operation ran but declined its result on its merits (an alignment that did not
/// converge or overlaps too little, a floor height that was not measured, an update larger than
/// its budget). Nothing was changed.
class RefusedError : public Error {
public:
    using Error::Error;
};

/// @brief The operating system failed a read or write (a full disk, no permission, a read-only
/// map opened for writing, a failed fsync).
class IoError : public Error {
public:
    using Error::Error;
};

}  // namespace strata
