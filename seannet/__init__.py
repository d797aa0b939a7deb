"""SeanNet: the scene-embedding network and its trainer (PyTorch side)."""

from seannet.backbones import ENCODER_NAMES, ResNetSplit, image_encoder, resnet_c4
from seannet.baselines import ImageEncoder
from seannet.batch import NUM_RELATIONS, SceneBatch
from seannet.config import PRESETS, TrainConfig, preset
from seannet.data import (
    ImageTransform,
    ObservationDataset,
    TripletDataset,
    collate_triplets,
    collate_views,
    dataset_identity,
)
from seannet.errors import CheckpointError, DataError, ModelError, SeannetError
from seannet.eval_run import evaluate_run
from seannet.loss import TripletLoss, similarity
from seannet.model import MODEL_NAMES, SeanNet, build_model
from seannet.pretrained import KNOWN_WEIGHTS, load_pretrained, load_state_dict_file
from seannet.train import train
from seannet.wordvectors import (
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
