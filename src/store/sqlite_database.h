#pragma once
// A thin RAII layer over the SQLite C API: the connection, prepared statements (reset per use) and
// a scoped transaction.
// Not thread-safe: one thread uses a connection and its statements at a time.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

struct sqlite3;
struct sqlite3_stmt;

namespace edgeslam {

class SqliteDatabase {
 public:
  // Throws StoreError naming the file. `create`: make the file when absent.
  SqliteDatabase(const std::filesystem::path& file, bool read_only, bool create);
  ~SqliteDatabase();
  SqliteDatabase(const SqliteDatabase&) = delete;
  SqliteDatabase& operator=(const SqliteDatabase&) = delete;

  void execute(const std::string& sql);
  sqlite3* handle() const { return db_; }
  const std::filesystem::path& file() const { return file_; }
  // "FILE: what failed: SQLite's message".
  [[noreturn]] void fail(const std::string& what) const;

 private:
  std::filesystem::path file_;
  sqlite3* db_ = nullptr;
};

class SqliteStatement {
 public:
  SqliteStatement(SqliteDatabase& db, const std::string& sql);
  ~SqliteStatement();
  SqliteStatement(const SqliteStatement&) = delete;
  SqliteStatement& operator=(const SqliteStatement&) = delete;

  // Binding indices start at 1, as in SQL.
  SqliteStatement& bind(int index, std::int64_t value);
  SqliteStatement& bind(int index, double value);
  SqliteStatement& bind(int index, const std::string& value);
  SqliteStatement& bindBlob(int index, std::span<const std::uint8_t> bytes);
  SqliteStatement& bindNull(int index);
  // True while a row is available; false when done. Throws on error.
  bool step();
  // Runs a statement that returns no rows, then resets it.
  void run();
  void reset();

  std::int64_t columnInt(int column) const;
  double columnDouble(int column) const;
  std::string columnText(int column) const;
  std::vector<std::uint8_t> columnBlob(int column) const;
  // The blob where SQLite holds it: valid until the next step() or reset(), no copy.
  std::span<const std::uint8_t> columnBlobView(int column) const;
  bool columnIsNull(int column) const;

 private:
  SqliteDatabase& db_;
  sqlite3_stmt* statement_ = nullptr;
};

// Rolls back when it leaves scope without commit() (an exception on the way): a batch is in the
// store whole or not at all.
class SqliteTransaction {
 public:
  explicit SqliteTransaction(SqliteDatabase& db);
  ~SqliteTransaction();
  SqliteTransaction(const SqliteTransaction&) = delete;
  SqliteTransaction& operator=(const SqliteTransaction&) = delete;

  void commit();  // throws StoreError (disk full, I/O error), having rolled back

 private:
  SqliteDatabase& db_;
  bool open_ = true;
};

}  // namespace edgeslam
