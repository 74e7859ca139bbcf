# Unit tests of src/scene/ (tissue_core_unit; explicit: a new test file is added here).
list(APPEND TISSUE_UNIT_TESTS
  test/unit/scene/test_liver_cut_scene.cpp
  test/unit/scene/test_organ_scene.cpp
  test/unit/scene/test_scene_loader.cpp
)
