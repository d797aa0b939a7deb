"""SeanNet's layers, one per module: box encoding, object embedding, multi-pathway GCN,
slot layout."""

from seannet.layers.box_encoding import BoxEncoding, sinusoidal_encoding
from seannet.layers.gcn import GCNLayer, GCNPathway, MultiPathwayGCN
from seannet.layers.object_embedding import ObjectEmbedding
from seannet.layers.slot_layout import SlotLayout, box_coverage

__all__ = [
    "BoxEncoding",
    "GCNLayer",
    "GCNPathway",
    "MultiPathwayGCN",
    "ObjectEmbedding",
    "SlotLayout",
    "box_coverage",
    "sinusoidal_encoding",
]
