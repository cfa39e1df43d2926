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
  add_custom_command(
    OUTPUT ${out_dir}/frames.jsonl
    COMMAND ${CMAKE_COMMAND} -E rm -rf ${out_dir}
    COMMAND ${simulate} simulate --scene ${scene_file} --out ${out_dir}
    DEPENDS $<TARGET_FILE:arpipe_sim> $<TARGET_FILE:arpipe_recording> ${scene_file}
    COMMENT "Simulating ${out_dir} (configs/sim/${scene}.toml)")
  add_custom_target(${target} ${ARGN} DEPENDS ${out_dir}/frames.jsonl)
  add_dependencies(${target} arpipe)
endfunction()
