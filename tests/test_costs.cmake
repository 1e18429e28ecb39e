# Read by ctest after the GoogleTest executables have listed their tests (TEST_INCLUDE_FILES, in
# tests/CMakeLists.txt). ctest -j starts the tests with the highest COST first, but it learns the
# costs only from an earlier run in the same build folder, which a clean CI clone never has: the
# ThreadSanitizer stage of 2026-11-29 started its longest test (314 s) last, alone on a core for
# minutes. The values are seconds under AddressSanitizer on a 2-core machine (Release in brackets
# where that stage runs them longer); only their order matters. A test not in this build (a
# sanitizer skips it) is ignored. The tests added with add_test
# (Python, Install, Viewer) get their COST where they are added.
set(_plslam_costs
  LoopClosingConcurrent.RenderedOfficeLoopClosesAtTheRevisitOnly 90
  RunSignals.StopAtAFrameBoundaryAndWriteEverything 60
  BenchSlamCli.ConcurrentRunsAgreeWithASeparateRunWithinTheirSpreadAndAnAnchorIsARow 57
  RelocalizationConcurrent.KidnappedKittiCameraIsFoundAgainWhileLocalMappingRuns 55
  LiveViewerRun.AClientFollowsTheMapAsItGrowsAndEndsOnTheFinalState 50
  Relocalization.WithoutPlaceRecognitionALostCameraStartsANewSegment 45
  Relocalization.KeepsFailingForOneSecondThenStartsANewSegment 45
  RunEndToEnd.Kitti06IsTrackedWithinBound 43
  RunEndToEnd.CorridorLinesLowerTheFrameToFrameError 36
  PublicApi.TracksASequenceWithPosesTheTrajectoryAndMapAgreeOn 33
  RunDeterminism.RepeatReportsTheSpreadOfSequentialRuns 31
  BlackOut.ALookAlikePlaceIsNotTakenForTheCamerasPlace 30
  PublicApi.SavedMapIsLoadedAndLocalizedIn 30
  RunConcurrent.Kitti06WithLocalMappingThread 30
  RunConcurrent.SyntheticOfficeWithLocalMappingThread 28
  LoopRun.SequentialRunsWithALoopAreIdentical 27
  RunConcurrent.EurocMicroWithLocalMappingThread 25
  BenchSlamCli.QuickPresetReportsEveryConfigurationAndMetricAsSeparateSequentialRunsDo 25
  BlackOut.AJumpToALookAlikePlaceIsNotTakenAfterABlackOut 24
  TimeRobustness.HighwayStartedOneFrameLateIsTrackedAtItsSpeed 22
  RunVideo.ASyntheticVideoTracksLikeItsImageFolders 20)
while(_plslam_costs)
  list(POP_FRONT _plslam_costs _name _cost)
  set_tests_properties(${_name} PROPERTIES COST ${_cost})
endwhile()
