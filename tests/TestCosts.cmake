# Read by ctest after each test folder's discovered tests (TEST_INCLUDE_FILES, appended in
# tests/CMakeLists.txt). ctest starts the costliest tests first, by the times it measured in the
# build folder (Testing/Temporary/CTestCostData.txt); a fresh clone (CI) has none and would start
# the tests in the order they are declared, leaving the slowest to the end with one core idle.
# These are the tests that take 10 s or more: seconds measured on 2026-12-04 (`.ci/run` on a
# 2-core machine, the larger of the normal and the ASan build). Tests of other folders and unknown
# names are ignored. The tests declared with add_test carry their COST where they are declared.
set(strata_test_costs
  MpiCli.VehiclesOnTwoAndThreeRanksAreTheOneProcessVehicles 109
  History.AFormat4MapIsMigratedWithEverySnapshotAndLayerIdentical 49
  VehiclesByTiles.StoredTileByTileTheCleanedMapIsTheWholeMapsVoxelForVoxel 45
  VehiclesByTiles.TileByTileClearsTheWholeMapsVehicles 40
  VehiclesByTiles.AGeometricObjectLongerThanTheBudgetAllowsIsRefusedNamingIt 40
  StoreFaults.KilledUpgradesLeaveTheOldFormatOrTheNew 36
  DistrictAccuracy.WholeMapScoresAsTheExampleScenes 34
  RegistrationRealDataOuster.TheTwoScansAreOfTwoPlacesAndRegistrationRefusesThem 31
  WallsByTiles.TileByTileFindsTheWholeMapsWalls 31
  WallsByTiles.ABudgetBelowOneTileAndItsHaloIsRefusedNamingTheFlag 24
  History.KeepLastDropsOlderSnapshotsAndKeepsTheRest 23
  RegistrationFloorsCli.StacksTwoFloorsAndLocalizesAScanOnTheFirst 23
  VehiclesSimulated.ParkingGarageClearedAndRefilledBeatsClearingAlone 21
  TileByTile.ChangesReadTileByTileAreTheWholeMapsChanges 18
  RegistrationRealData.Kitti00FramesLandOnTheRawPointOptimumAndAmongTheStereoReferences 18
  Store.AFailedCommitLeavesThePreviousCommitAndNoFiles 18
  PipelineStack.RefusesAnUnmeasuredHeightThenStacksTwoStoreysFromTheZBias 18
  StoreFaults.ReaderProcessesSeeWholeCommitsWhileAWriterCommits 16
  RegistrationFloors.MeasuresZThroughTheStairwellFromAWrongZBias 16
  StoreFaults.KilledHistoryDropsLeaveTheHistoryBeforeOrAfter 16
  History.KeepSinceKeepsTheSnapshotCurrentAtTheDate 15
  MpiCli.WallsOnTwoAndThreeRanksAreTheOneProcessWalls 14
  RegistrationFloors.StacksTheCorridorOnlyBuildingInXyYawButRefusesToGuessZ 14
  MpiCli.IntegrateOnTwoAndThreeRanksGivesTheOneProcessMap 13
  OctomapAgreement.BalmFiveScansAt10cmEqualOctomap 13
  PipelineVehicles.ClearsTheParkedCarsAndStoresTheCleanedMapAsOneCommit 13
  Store.MemoryBudgetEvictsTilesAndGivesTheSameMap 12
  RankedSession.EveryRankCountGivesTheMapOneProcessGives 12
  RegistrationFloors.RefusesZWhenNeitherStoreyEnteredTheStairwell 11
  PipelineVehicles.StoringFromAReaderIsRefused 11
  OctomapAgreement.Kitti00TwoFramesAt10cmEqualOctomap 11
  RegistrationRealDataOuster.HalvesOfOneSweepAlignAtTheIdentity 10
  RegistrationFloorsCli.MeasuresAndRecordsZThroughTheStairwell 10
  Store.RemovingASessionRebuildsOnlyWhatItSaw 10
  SessionWorkers.ASessionSplitBetweenWritersIsTheSessionOneWriterMakes 10
  District.FullDistrictIsAboutOneKilometreSquareWithThreeSessions 10
  Store.CommitsWriteTheSameBytesWhateverTheMapsAge 10)
while(strata_test_costs)
  list(POP_FRONT strata_test_costs test cost)
  set_tests_properties(${test} PROPERTIES COST ${cost})
endwhile()
