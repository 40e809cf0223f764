#pragma once
// The runner's table from a Monte Carlo study's records (study_part.hpp): its rows, and --merge.
#include <string>
#include <utility>
#include <vector>

#include "study_part.hpp"
#include "table_row.hpp"

namespace sextant::runner {

/// The table's rows of merged records: a row per cell, in order; its scores the average of its runs
/// in seed order (eval::summarize); failed when one of its runs failed (the first such seed's message);
/// the first seed's association when the runs have one.
std::vector<TableRow> rows_of(const std::vector<eval::StudyRecord>& records);

/// The association's numbers as a record's extras.
std::vector<std::pair<std::string, double>> association_extras(const AssociationRow& a);
/// A FastSLAM run's cloud at its end as a record's extras (read back by the table's row).
std::vector<std::pair<std::string, double>> cloud_extras(const CloudRow& cloud);
/// An ESEIF run's relocalizations as a record's extras (read back by the table's row).
std::vector<std::pair<std::string, double>> relocalization_extras(const RelocalizationRow& relocalization);

/// A GraphSLAM run's final optimization as a record's extras (the table's row counts the unconverged).
std::vector<std::pair<std::string, double>> optimization_extras(const OptimizationRow& optimization);

/// --merge: prints the table of the study whose record files (or directories of them) are `paths`
/// and returns its rows.
std::vector<TableRow> merged_rows(const std::string& program, const std::vector<std::string>& paths);

}  // namespace sextant::runner
