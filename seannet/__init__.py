"""SeanNet: the scene-embedding network and its trainer (PyTorch side)."""

from .backbones import ENCODER_NAMES, ResNetSplit, image_encoder, resnet_c4
from .baselines import ImageEncoder
from .batch import NUM_RELATIONS, SceneBatch
from .config import PRESETS, TrainConfig, preset
from .data import (
    ImageTransform,
    ObservationDataset,
    TripletDataset,
    collate_triplets,
    collate_views,
    dataset_identity,
)
from .errors import CheckpointError, DataError, ModelError, SeannetError
from .eval_run import evaluate_run
from .loss import TripletLoss, similarity
from .model import MODEL_NAMES, SeanNet, build_model
from .pretrained import KNOWN_WEIGHTS, load_pretrained, load_state_dict_file
from .train import train
from .wordvectors import (
    WordVectorTable,
    build_table,
    load_table,
    save_table,
    split_camel_case,
    write_word_vectors,
)

__all__ = [
    "ImageTransform",
    "ObservationDataset",
    "PRESETS",
    "TrainConfig",
    "TripletDataset",
    "collate_triplets",
    "collate_views",
    "dataset_identity",
    "evaluate_run",
    "preset",
    "train",
    "CheckpointError",
    "DataError",
    "ENCODER_NAMES",
    "ImageEncoder",
    "KNOWN_WEIGHTS",
    "MODEL_NAMES",
    "ModelError",
    "NUM_RELATIONS",
    "ResNetSplit",
    "SceneBatch",
    "SeanNet",
    "SeannetError",
    "TripletLoss",
    "WordVectorTable",
    "build_model",
    "build_table",
    "image_encoder",
    "load_pretrained",
    "load_state_dict_file",
    "load_table",
    "resnet_c4",
    "save_table",
    "similarity",
    "split_camel_case",
    "write_word_vectors",
]
