#pragma once
// Private to the store: a thin RAII layer over SQLite (connection, statement, transaction) whose
// errors are kinds of strata::Error naming the catalog file.

#include <cstdint>
#include <filesystem>
#include <string>

struct sqlite3;
struct sqlite3_stmt;

namespace strata::store::detail {

class Database;

/// Throws the strata::Error kind for an SQLite result code: FormatError for a damaged or foreign
/// file, IoError for a failed read or write, Error otherwise.
[[noreturn]] void ThrowKind(int sqlite_code, const std::string& message);

/// A prepared statement; columns and parameters are numbered as in SQLite (bind from 1, read
/// from 0).
class Statement {
public:
    Statement(const Database& db, const char* sql);
    ~Statement();
    Statement(const Statement&) = delete;
    Statement& operator=(const Statement&) = delete;

    Statement& Bind(int i, int64_t value);
    Statement& Bind(int i, double value);
    Statement& Bind(int i, const std::string& value);
    Statement& BindNull(int i);

    /// Advances; true while there is a row to read.
    bool Step();
    /// Runs a statement that returns no rows.
    void Run();
    void Reset();

    [[nodiscard]] int64_t Int(int column) const;
    [[nodiscard]] double Real(int column) const;
    [[nodiscard]] std::string Text(int column) const;
    [[nodiscard]] bool IsNull(int column) const;

private:
    const Database& db_;
    sqlite3_stmt* stmt_ = nullptr;
};

/// One connection to a catalog file.
class Database {
public:
    enum class Mode { kReadOnly, kReadWrite, kCreate };

    /// Opens `file`; a read-only open of a map on read-only media falls back to SQLite's
    /// immutable mode (nobody can write it, so no locks are needed).
    Database(const std::filesystem::path& file, Mode mode);
    ~Database();
    Database(const Database&) = delete;
    Database& operator=(const Database&) = delete;

    void Exec(const char* sql) const;
    [[nodiscard]] Statement Prepare(const char* sql) const { return Statement(*this, sql); }
    [[nodiscard]] int64_t LastInsertId() const;

    /// Throws a kind of strata::Error: "<file>: <what> (<SQLite's message>)".
    [[noreturn]] void Fail(const std::string& what) const;
    [[nodiscard]] sqlite3* handle() const { return db_; }
    [[nodiscard]] const std::filesystem::path& file() const { return file_; }

private:
    std::filesystem::path file_;
    sqlite3* db_ = nullptr;
};

/// BEGIN on construction (IMMEDIATE for writers, so the write lock is taken up front), ROLLBACK
/// on destruction unless Commit() ran.
class Transaction {
public:
    enum class Kind { kRead, kWrite };
    Transaction(const Database& db, Kind kind);
    ~Transaction();
    Transaction(const Transaction&) = delete;
    Transaction& operator=(const Transaction&) = delete;
    void Commit();

private:
    const Database& db_;
    bool open_ = true;
};

}  // namespace strata::store::detail
