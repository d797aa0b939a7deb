"""SeanNet's layers, one per module: box encoding, object embedding, multi-pathway GCN, the
linear layer on column runs of its fc, slot layout."""

from seannet.model.layers.box_encoding import BoxEncoding, sinusoidal_encoding
from seannet.model.layers.column_linear import ColumnLinear
from seannet.model.layers.gcn import GCNLayer, GCNPathway, MultiPathwayGCN
from seannet.model.layers.object_embedding import ObjectEmbedding
from seannet.model.layers.slot_layout import SlotLayout, box_coverage

__all__ = [
    "BoxEncoding",
    "ColumnLinear",
    "GCNLayer",
    "GCNPathway",
    "MultiPathwayGCN",
    "ObjectEmbedding",
    "SlotLayout",
    "box_coverage",
    "sinusoidal_encoding",
]
