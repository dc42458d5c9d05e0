# neuflowd's systemd units (systemd/*.service.in): systemd-analyze verify on both, their
# exposure as systemd-analyze security rates it, the template kept hardened like the single
# unit, and the units `cmake --install` writes. Skipped (77) without systemd-analyze.
set(neuflow_units_script ${CMAKE_CURRENT_SOURCE_DIR}/systemd_units.sh)
foreach(mode verify security alike)
  add_test(NAME neuflowd.systemd_${mode}
    COMMAND bash ${neuflow_units_script} ${mode} ${PROJECT_SOURCE_DIR}/systemd $<TARGET_FILE:neuflowd>
            ${CMAKE_CURRENT_BINARY_DIR}/systemd-${mode})
endforeach()
add_test(NAME neuflowd.systemd_installed
  COMMAND bash ${neuflow_units_script} installed ${PROJECT_BINARY_DIR} $<TARGET_FILE:neuflowd>
          ${CMAKE_CURRENT_BINARY_DIR}/systemd-installed)
set_tests_properties(neuflowd.systemd_verify neuflowd.systemd_security neuflowd.systemd_alike
  neuflowd.systemd_installed PROPERTIES SKIP_RETURN_CODE 77 LABELS daemon)
