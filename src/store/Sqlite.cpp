#include "Sqlite.hpp"

#include <sqlite3.h>
#include <unistd.h>

#include <stdexcept>

#include "strata/core/Error.hpp"

namespace strata::store::detail {

void ThrowKind(int sqlite_code, const std::string& message) {
    switch (sqlite_code & 0xff) {
        case SQLITE_CORRUPT:
        case SQLITE_NOTADB:
        case SQLITE_FORMAT:
        case SQLITE_SCHEMA:
            throw FormatError(message);
        case SQLITE_IOERR:
        case SQLITE_FULL:
        case SQLITE_CANTOPEN:
        case SQLITE_READONLY:
        case SQLITE_PERM:
            throw IoError(message);
        default:
            throw Error(message);
    }
}

Statement::Statement(const Database& db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db.handle(), sql, -1, &stmt_, nullptr) != SQLITE_OK) {
        db.Fail(std::string("cannot prepare '") + sql + "'");
    }
}

Statement::~Statement() { sqlite3_finalize(stmt_); }

Statement& Statement::Bind(int i, int64_t value) {
    if (sqlite3_bind_int64(stmt_, i, value) != SQLITE_OK) db_.Fail("cannot bind a parameter");
    return *this;
}

Statement& Statement::Bind(int i, double value) {
    if (sqlite3_bind_double(stmt_, i, value) != SQLITE_OK) db_.Fail("cannot bind a parameter");
    return *this;
}

Statement& Statement::Bind(int i, const std::string& value) {
    if (sqlite3_bind_text(stmt_, i, value.data(), static_cast<int>(value.size()),
                          SQLITE_TRANSIENT) != SQLITE_OK) {
        db_.Fail("cannot bind a parameter");
    }
    return *this;
}

Statement& Statement::BindNull(int i) {
    if (sqlite3_bind_null(stmt_, i) != SQLITE_OK) db_.Fail("cannot bind a parameter");
    return *this;
}

bool Statement::Step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    db_.Fail(std::string("query failed: ") + sqlite3_sql(stmt_));
}

void Statement::Run() {
    while (Step()) {
    }
}

void Statement::Reset() {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
}

int64_t Statement::Int(int column) const { return sqlite3_column_int64(stmt_, column); }

double Statement::Real(int column) const { return sqlite3_column_double(stmt_, column); }

std::string Statement::Text(int column) const {
    const auto* text = sqlite3_column_text(stmt_, column);
    return text ? std::string(reinterpret_cast<const char*>(text),
                              static_cast<size_t>(sqlite3_column_bytes(stmt_, column)))
                : std::string();
}

bool Statement::IsNull(int column) const {
    return sqlite3_column_type(stmt_, column) == SQLITE_NULL;
}

Database::Database(const std::filesystem::path& file, Mode mode) : file_(file) {
    const auto open = [&](const std::string& name, int flags) {
        sqlite3_close(db_);
        db_ = nullptr;
        const int rc = sqlite3_open_v2(name.c_str(), &db_, flags | SQLITE_OPEN_URI, nullptr);
        if (rc == SQLITE_OK) return true;
        return false;
    };
    int flags = mode == Mode::kReadOnly ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE;
    if (mode == Mode::kCreate) flags |= SQLITE_OPEN_CREATE;
    // A constructor that throws never runs the destructor: close the connection here, or each
    // refused catalog keeps a file descriptor (fuzz_catalog ran out of them after 23000 inputs).
    try {
        if (!open(file.string(), flags)) Fail("cannot open the catalog");
        sqlite3_extended_result_codes(db_, 1);
        // Writers hold the map's lock file, so SQLite's own lock is only ever contended for the
        // instant a reader checkpoints; wait for it instead of failing.
        sqlite3_busy_timeout(db_, 10000);
        if (mode != Mode::kReadOnly) return;
        // A WAL database needs its -shm file; on a read-only directory SQLite cannot create it.
        if (sqlite3_exec(db_, "SELECT count(*) FROM sqlite_master", nullptr, nullptr, nullptr) ==
            SQLITE_OK) {
            return;
        }
        if (::access(file.parent_path().c_str(), W_OK) == 0) Fail("cannot read the catalog");
        if (!open("file:" + file.string() + "?immutable=1", SQLITE_OPEN_READONLY)) {
            Fail("cannot open the catalog (read-only media)");
        }
    } catch (...) {
        sqlite3_close(db_);
        db_ = nullptr;
        throw;
    }
}

Database::~Database() { sqlite3_close(db_); }

void Database::Exec(const char* sql) const {
    char* message = nullptr;
    const int rc = sqlite3_exec(db_, sql, nullptr, nullptr, &message);
    if (rc != SQLITE_OK) {
        const std::string what = message ? message : "unknown error";
        sqlite3_free(message);
        ThrowKind(rc, file_.string() + ": " + what);
    }
}

int64_t Database::LastInsertId() const { return sqlite3_last_insert_rowid(db_); }

void Database::Fail(const std::string& what) const {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    ThrowKind(db_ ? sqlite3_extended_errcode(db_) : SQLITE_NOMEM,
              file_.string() + ": " + what + " (" + why + ")");
}

Transaction::Transaction(const Database& db, Kind kind) : db_(db) {
    db_.Exec(kind == Kind::kWrite ? "BEGIN IMMEDIATE" : "BEGIN");
}

Transaction::~Transaction() {
    if (open_) sqlite3_exec(db_.handle(), "ROLLBACK", nullptr, nullptr, nullptr);
}

void Transaction::Commit() {
    db_.Exec("COMMIT");
    open_ = false;
}

}  // namespace strata::store::detail
