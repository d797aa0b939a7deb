"""SeanNet's layers, one per module: box encoding, object embedding, multi-pathway GCN."""

from seannet.layers.box_encoding import BoxEncoding, sinusoidal_encoding
from seannet.layers.gcn import GCNLayer, GCNPathway, MultiPathwayGCN
from seannet.layers.object_embedding import ObjectEmbedding

__all__ = [
    "BoxEncoding",
    "GCNLayer",
    "GCNPathway",
    "MultiPathwayGCN",
    "ObjectEmbedding",
    "sinusoidal_encoding",
]
