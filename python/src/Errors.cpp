// Each kind of strata::Error becomes a Python class of the same name under strata.Error; the
// older std::invalid_argument / std::runtime_error the library still throws in places map to
// InvalidArgumentError / Error, so a caller never has to catch RuntimeError.
#include <exception>
#include <stdexcept>

#include "Bindings.hpp"
#include "strata/core/Error.hpp"

namespace strata::python {

namespace {

struct ErrorClasses {
    py::object base, invalid_argument, format, not_found, locked, refused, io;
};

ErrorClasses& Classes() {
    static ErrorClasses* classes = new ErrorClasses();  // outlives the interpreter's teardown
    return *classes;
}

py::object NewError(py::module_& m, const char* name, py::handle bases, const char* doc) {
    const std::string qualified = "strata." + std::string(name);
    py::object cls = py::reinterpret_steal<py::object>(
        PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr));
    if (!cls) throw py::error_already_set();
    m.attr(name) = cls;
    return cls;
}

}  // namespace

void RegisterErrors(py::module_& m) {
    ErrorClasses& c = Classes();
    const py::module_ builtins = py::module_::import("builtins");
    c.base = NewError(m, "Error", builtins.attr("RuntimeError"),
                      "Base of every error strata raises; the message names the file, argument "
                      "or map at fault.");
    // Subclasses also derive from the builtin a Python caller would catch for the same problem.
    const auto both = [&](const char* builtin) {
        return py::make_tuple(c.base, builtins.attr(builtin));
    };
    c.invalid_argument = NewError(m, "InvalidArgumentError", both("ValueError"),
                                  "A bad argument, array or config value.");
    c.format = NewError(m, "FormatError", both("ValueError"),
                        "A malformed file, or a map of a newer format.");
    c.not_found = NewError(m, "NotFoundError", both("LookupError"),
                           "A map, session or input file that does not exist.");
    c.locked = NewError(m, "MapLockedError", py::make_tuple(c.base),
                        "Another process writes the map; retrying later can succeed.");
    c.refused = NewError(m, "RefusedError", py::make_tuple(c.base),
                         "The operation ran and declined its result; nothing was changed.");
    c.io = NewError(m, "IoError", both("OSError"), "The operating system failed a read or write.");

    py::register_exception_translator([](std::exception_ptr p) {
        const ErrorClasses& k = Classes();
        const auto raise = [](const py::object& cls, const std::exception& e) {
            PyErr_SetString(cls.ptr(), e.what());
        };
        try {
            if (p) std::rethrow_exception(p);
        } catch (const py::builtin_exception&) {
            throw;  // pybind11's own (cast errors and the like): its translator handles them
        } catch (const InvalidArgumentError& e) {
            raise(k.invalid_argument, e);
        } catch (const FormatError& e) {
            raise(k.format, e);
        } catch (const NotFoundError& e) {
            raise(k.not_found, e);
        } catch (const MapLockedError& e) {
            raise(k.locked, e);
        } catch (const RefusedError& e) {
            raise(k.refused, e);
        } catch (const IoError& e) {
            raise(k.io, e);
        } catch (const Error& e) {
            raise(k.base, e);
        } catch (const std::invalid_argument& e) {
            raise(k.invalid_argument, e);
        } catch (const std::out_of_range& e) {
            raise(k.invalid_argument, e);
        } catch (const std::runtime_error& e) {
            raise(k.base, e);
        }
    });
}

}  // namespace strata::python
