// The time-series recorder both solvers share (solvers/common/series_recorder.hpp): columns
// set by name, rows that must be whole, and the energy budget's columns on totals of known
// budget.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "common/series_recorder.hpp"

namespace shaker {
namespace {

TEST(SeriesRecorder, ColumnsKeepTheFirstRowsOrderWhateverTheOrderOfLaterRows) {
  SeriesRecorder rows;
  rows.set("t", 0.0);
  rows.set("com_z", 4.0);
  rows.end_row();
  rows.set("com_z", 5.0);
  rows.set("t", 1.0);
  rows.end_row();
  const TimeSeries series = rows.finish();
  EXPECT_EQ(series.names, (std::vector<std::string>{"t", "com_z"}));
  EXPECT_EQ(series.column("t"), (std::vector<double>{0.0, 1.0}));
  EXPECT_EQ(series.column("com_z"), (std::vector<double>{4.0, 5.0}));
}

TEST(SeriesRecorder, RefusesARowThatMissesRepeatsOrAddsAColumn) {
  SeriesRecorder rows;
  rows.set("t", 0.0);
  rows.set("com_z", 4.0);
  rows.end_row();
  rows.set("t", 1.0);
  EXPECT_THROW(rows.end_row(), std::logic_error);  // com_z missing
  EXPECT_THROW(rows.set("t", 2.0), std::logic_error);  // t twice in the row
  EXPECT_THROW(rows.set("plate_z", 0.0), std::logic_error);  // not a column of the first row
}

TEST(SeriesRecorder, EnergyBudgetColumnsCountTheResidualFromTheFirstRow) {
  SeriesRecorder rows;
  // A continued run: the running totals do not start at zero.
  rows.set_energy(EnergyTotals{10.0, 100.0, 50.0, 1.0});
  rows.end_row();
  // Energy change 2, work 5, loss 2.5, floor 0.25: residual 2 - 5 + 2.5 - 0.25 = -0.75,
  // relative to the largest of |5|, |2.5| and the energy 12.
  rows.set_energy(EnergyTotals{12.0, 105.0, 52.5, 1.25});
  rows.end_row();
  const TimeSeries series = rows.finish();
  EXPECT_EQ(series.names, (std::vector<std::string>{"accumulated_drive_work", "accumulated_collisional_loss",
                                                    "accumulated_floor_energy", "energy_budget_residual",
                                                    "energy_budget_relative_residual"}));
  EXPECT_EQ(series.column("accumulated_drive_work"), (std::vector<double>{100.0, 105.0}));
  EXPECT_EQ(series.column("accumulated_collisional_loss"), (std::vector<double>{50.0, 52.5}));
  EXPECT_EQ(series.column("accumulated_floor_energy"), (std::vector<double>{1.0, 1.25}));
  EXPECT_EQ(series.column("energy_budget_residual"), (std::vector<double>{0.0, -0.75}));
  EXPECT_EQ(series.column("energy_budget_relative_residual"), (std::vector<double>{0.0, 0.0625}));
}

TEST(SeriesRecorder, WithoutAFloorThereIsNoFloorColumn) {
  SeriesRecorder rows;
  rows.set_energy(EnergyTotals{3.0, 0.0, 0.0, std::nullopt});
  rows.end_row();
  EXPECT_FALSE(rows.series().has("accumulated_floor_energy"));
  EXPECT_TRUE(rows.series().has("energy_budget_relative_residual"));
}

TEST(EnergyBalance, ClosesABudgetOfKnownTerms) {
  const EnergyBalance b = balance(EnergyTotals{1.0, 2.0, 3.0, std::nullopt}, EnergyTotals{2.0, 10.0, 10.0, std::nullopt});
  EXPECT_EQ(b.drive_work, 8.0);
  EXPECT_EQ(b.collisional_loss, 7.0);
  EXPECT_EQ(b.energy_change, 1.0);
  EXPECT_EQ(b.residual, 0.0);  // 1 = 8 - 7
  EXPECT_EQ(b.relative_residual, 0.0);
}

}  // namespace
}  // namespace shaker
