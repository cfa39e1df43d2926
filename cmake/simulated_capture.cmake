# Captures simulated at build time from a scene in configs/sim (never committed): the embedded
# default and the tests' captures. ARPIPE_SIMULATOR, when set, is the arpipe that simulates them
# (the same bits, a fraction of the time); ARPIPE_CAPTURES_FROM, when set, is a build directory
# whose captures are copied instead (CI's sanitizer build takes the plain build's).
# Usage: arpipe_simulated_capture(TARGET SCENE OUT_DIR [ALL])
function(arpipe_simulated_capture target scene out_dir)
  set(scene_file ${PROJECT_SOURCE_DIR}/configs/sim/${scene}.toml)
  get_filename_component(capture_name ${out_dir} NAME)
  if(ARPIPE_CAPTURES_FROM)
    # Another build of the same sources already simulated it (CI's sanitizer build reuses the
    # plain build's captures: the same simulator gives the same bits, minutes sooner).
    add_custom_command(
      OUTPUT ${out_dir}/frames.jsonl
      COMMAND ${CMAKE_COMMAND} -E rm -rf ${out_dir}
      COMMAND ${CMAKE_COMMAND} -E copy_directory ${ARPIPE_CAPTURES_FROM}/${capture_name} ${out_dir}
      DEPENDS ${ARPIPE_CAPTURES_FROM}/${capture_name}/frames.jsonl ${scene_file}
      COMMENT "Copying ${out_dir} from ${ARPIPE_CAPTURES_FROM}")
    add_custom_target(${target} ${ARGN} DEPENDS ${out_dir}/frames.jsonl)
    return()
  endif()
  if(ARPIPE_SIMULATOR)
    set(simulate ${ARPIPE_SIMULATOR})
  else()
    set(simulate arpipe)
  endif()
  # Simulated again when the simulator's code or the scene changes, not on every relink of arpipe
  # (a new subcommand would otherwise re-simulate every capture, minutes each). A change in core
  # that the simulator uses without recompiling (rare) needs the capture deleted by hand.
  # And when a file the scene names changes (a texture picture, a camera model): every quoted value
  # outside a comment that names an existing file beside the scene. The scene file is a configure
  # dependency, so a newly named file is picked up too.
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${scene_file})
  file(STRINGS ${scene_file} quoted_lines REGEX "^[^#]*=[ \t]*\"[^\"]+\"")
  set(scene_assets "")
  foreach(line IN LISTS quoted_lines)
    string(REGEX REPLACE "^[^#]*=[ \t]*\"([^\"]+)\".*" "\\1" referenced "${line}")
    set(asset "${PROJECT_SOURCE_DIR}/configs/sim/${referenced}")
    if(referenced MATCHES "^[A-Za-z0-9_./-]+$" AND NOT IS_DIRECTORY "${asset}" AND EXISTS "${asset}")
      list(APPEND scene_assets ${asset})
    endif()
  endforeach()
  add_custom_command(
    OUTPUT ${out_dir}/frames.jsonl
    COMMAND ${CMAKE_COMMAND} -E rm -rf ${out_dir}
    COMMAND ${simulate} simulate --scene ${scene_file} --out ${out_dir}
    DEPENDS $<TARGET_FILE:arpipe_sim> $<TARGET_FILE:arpipe_recording> ${scene_file} ${scene_assets}
    COMMENT "Simulating ${out_dir} (configs/sim/${scene}.toml)")
  add_custom_target(${target} ${ARGN} DEPENDS ${out_dir}/frames.jsonl)
  add_dependencies(${target} arpipe)
endfunction()
