# Captures simulated at build time from a scene in configs/sim (never committed): the embedded
# default and the tests' captures. ARPIPE_SIMULATOR, when set, is the arpipe that simulates them
# (CI's sanitizer build uses the plain build's: the same bits, a fraction of the time).
# Usage: arpipe_simulated_capture(TARGET SCENE OUT_DIR [ALL])
function(arpipe_simulated_capture target scene out_dir)
  set(scene_file ${PROJECT_SOURCE_DIR}/configs/sim/${scene}.toml)
  if(ARPIPE_SIMULATOR)
    set(simulate ${ARPIPE_SIMULATOR})
  else()
    set(simulate arpipe)
  endif()
  add_custom_command(
    OUTPUT ${out_dir}/frames.jsonl
    COMMAND ${CMAKE_COMMAND} -E rm -rf ${out_dir}
    COMMAND ${simulate} simulate --scene ${scene_file} --out ${out_dir}
    DEPENDS arpipe ${scene_file}
    COMMENT "Simulating ${out_dir} (configs/sim/${scene}.toml)")
  add_custom_target(${target} ${ARGN} DEPENDS ${out_dir}/frames.jsonl)
endfunction()
