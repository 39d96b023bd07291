"""Small helpers shared by every package of capt-env (``capt_env``, ``perception``, ``agents``) that
belong to none of them: typed YAML configs (:mod:`capt_common.typed_yaml`) and JSON/Markdown reports
of a command's numbers (:mod:`capt_common.json_report`). Standard library and PyYAML only."""
