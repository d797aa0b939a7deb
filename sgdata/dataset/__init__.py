"""The on-disk dataset: path templates, schemas, rows and Parquet writing, manifest, reader.

Writer side (used by ``sgdata generate``): :func:`observation_table`, :func:`triplet_table`,
:func:`write_parquet`, :class:`Manifest`, :func:`write_manifest`. Reader side:
:class:`Dataset`. The format itself is described in docs/dataset.md. Importing this package
loads no USD, renderer or torch.
"""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "ClassEntry": ".manifest",
    "Counts": ".manifest",
    "FORMAT_NAME": ".manifest",
    "FileEntry": ".manifest",
    "Generator": ".manifest",
    "ImageInfo": ".manifest",
    "Manifest": ".manifest",
    "classes_from_slots": ".manifest",
    "file_entry": ".manifest",
    "read_manifest": ".manifest",
    "relation_type_names": ".manifest",
    "write_manifest": ".manifest",
    "MANIFEST": ".paths",
    "OBSERVATIONS": ".paths",
    "OUTPUTS": ".paths",
    "ObsKey": ".paths",
    "SCENES": ".paths",
    "SCENE_LAYER": ".paths",
    "SCENE_ROOM": ".paths",
    "SCENE_TEXTURES": ".paths",
    "SPLITS": ".paths",
    "TRIPLETS": ".paths",
    "obs_id": ".paths",
    "observations_path": ".paths",
    "parse_obs_id": ".paths",
    "scene_dir": ".paths",
    "scene_layer_path": ".paths",
    "triplets_path": ".paths",
    "Dataset": ".reader",
    "decode_image": ".reader",
    "read_table": ".reader",
    "IMAGE_FORMATS": ".rows",
    "PARQUET_OPTIONS": ".rows",
    "ParquetInfo": ".rows",
    "encode_image": ".rows",
    "observation_table": ".rows",
    "sha256_file": ".rows",
    "triplet_table": ".rows",
    "write_parquet": ".rows",
    "FORMAT_VERSION": ".schema",
    "OLDEST_READABLE": ".schema",
    "file_schema": ".schema",
    "FormatVersionError": ".schema",
    "MIGRATIONS": ".schema",
    "SCHEMA_PACKAGE": ".schema",
    "check_compatible": ".schema",
    "manifest_json_schema": ".schema",
    "migrate_manifest_dict": ".schema",
    "observations_schema": ".schema",
    "parse_table_schema": ".schema",
    "schema_at": ".schema",
    "schema_markdown": ".schema",
    "since": ".schema",
    "table_schema": ".schema",
    "triplets_schema": ".schema",
    "class_vocabulary": ".vocabulary",
    "IMAGE_STORAGE": ".storage",
    "image_bytes": ".storage",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
