"""The pipeline: generation config, ``sgdata generate``, per-room tasks, ledger and executors."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "AnnotationConfig": ".config",
    "DatasetConfig": ".config",
    "GenerateConfig": ".config",
    "INTERNAL": ".config",
    "SPARSE": ".config",
    "ImagesConfig": ".config",
    "LayoutsConfig": ".config",
    "PRESETS": ".config",
    "PosesConfig": ".config",
    "ROOM_TYPE_NAME": ".config",
    "RoomFile": ".config",
    "RoomsConfig": ".config",
    "TripletsConfig": ".config",
    "config_to_dict": ".config",
    "load_config": ".config",
    "EXECUTORS": ".executors",
    "WORKER_ENV": ".executors",
    "die_with_parent": ".executors",
    "executor_session": ".executors",
    "run_tasks": ".executors",
    "GenerateProgress": ".generate",
    "generate_dataset": ".generate",
    "plan_rooms": ".generate",
    "CONFIG_RECORD": ".ledger",
    "LEDGER": ".ledger",
    "read_record": ".ledger",
    "scene_record": ".ledger",
    "views_record": ".ledger",
    "write_record": ".ledger",
    "RoomTask": ".room_tasks",
    "render_room_views": ".room_tasks",
    "write_room_scenes": ".room_tasks",
    "render_snapshot": ".snapshot",
    "resolve_user_rooms": ".user_rooms",
    "copy_user_room": ".user_rooms",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
