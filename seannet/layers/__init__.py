"""SeanNet's layers, one per module: box encoding, object embedding, multi-pathway GCN."""

from .box_encoding import BoxEncoding, sinusoidal_encoding
from .gcn import GCNLayer, GCNPathway, MultiPathwayGCN
from .object_embedding import ObjectEmbedding

__all__ = [
    "BoxEncoding",
    "GCNLayer",
    "GCNPathway",
    "MultiPathwayGCN",
    "ObjectEmbedding",
    "sinusoidal_encoding",
]
