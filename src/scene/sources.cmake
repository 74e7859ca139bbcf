# The scene stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/scene/pose_check.cpp
  src/scene/scene_loader.cpp
  src/scene/selectors.cpp
  src/scene/yaml_fields.cpp
)
