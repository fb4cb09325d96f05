// libFuzzer harness: CSV series of a run directory (io/csv_table.hpp: CsvTable), read by the report and the
// SVG plots from any run directory. Every column is read as numbers and as text, and the rows grouped by the
// first column: each either works or is an InputError naming the file.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/csv_table.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pegasus::fuzz::refuses_input_past_its_limit(
      [](const std::string& file) {
        if (!pegasus::CsvTable::load(file)) throw pegasus::InputError(file + ": not a regular file");
      },
      pegasus::kMaxDataFileBytes);
  static const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("pegasus-csv-fuzz-" + std::to_string(::getpid()) + ".csv");
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  pegasus::fuzz::keeps_error_contract(file.filename().string(), [&] {
    const auto table = pegasus::CsvTable::load(file);
    if (!table) pegasus::fuzz::violation("a written file reported absent", file.string());
    for (const auto& column : table->header()) {
      if (table->texts(column).size() != table->rows())
        pegasus::fuzz::violation("a column of another length", column);
      if (table->numeric(column) && table->numbers(column).size() != table->rows())
        pegasus::fuzz::violation("a numeric column of another length", column);
    }
    std::size_t rows = 0;
    if (!table->header().empty()) {
      for (const auto& group : table->groups({table->header().front()})) rows += group.second.size();
      if (rows != table->rows()) pegasus::fuzz::violation("groups that do not cover the rows", file.string());
    }
  });
  return 0;
}
