"""Stage 2, model: SeanNet, its layers, the image baselines, backbones, pretrained weights,
word vectors, the triplet loss and ``build_model``; ``ModelConfig`` holds their defaults."""

from sgdata.lazy_face import lazy_face

_EXPORTS = {
    "ENCODER_NAMES": ".backbones",
    "ResNetSplit": ".backbones",
    "image_encoder": ".backbones",
    "resnet_c4": ".backbones",
    "ImageEncoder": ".baselines",
    "ModelConfig": ".config",
    "ABLATIONS": ".specs",
    "MODEL_NAMES": ".specs",
    "parse_spec": ".specs",
    "build_model": ".factory",
    "TripletLoss": ".loss",
    "similarity": ".loss",
    "load_pretrained": ".pretrained",
    "load_state_dict_file": ".pretrained",
    "SeanNet": ".seannet",
    "WordVectorTable": ".wordvectors",
    "load_table": ".wordvectors",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_face(__name__, _EXPORTS)
