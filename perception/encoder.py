"""PCT encoder (paper Sec. III-A; Guo et al. 2021, "PCT: Point Cloud Transformer"), segmentation form.

Input embedding (two point-wise LBR layers), neighbour embedding (kNN grouping as PCT's SG module but
keeping all n points, so features stay per point), four offset-attention layers of width d_e whose
outputs are concatenated to (B, n, 4*d_e), and a global feature (max and mean pool of a fused
projection) that the heads may broadcast to every point, as PCT's segmentation head does.
"""

from __future__ import annotations

import torch
from torch import nn

from perception.pointwise import PointwiseConv1d, PointwiseConv2d


def knn_indices(xyz: torch.Tensor, k: int) -> torch.Tensor:
    """Indices (B, n, k) of each point's k nearest neighbours (itself included) in ``xyz`` (B, n, 3).

    Ranks row i by |x_j|^2 - 2 x_i . x_j, the squared distance less the row's constant |x_i|^2: one
    batched product, no square root."""
    sq = xyz.square().sum(dim=-1).unsqueeze(1)  # (B, 1, n)
    score = torch.baddbmm(sq, xyz, xyz.transpose(1, 2), alpha=-2.0)
    return score.topk(k, dim=-1, largest=False).indices


def gather_neighbours(feat: torch.Tensor, idx: torch.Tensor) -> torch.Tensor:
    """Features (B, C, n) gathered at ``idx`` (B, n, k) -> (B, C, n, k)."""
    b, c, n = feat.shape
    k = idx.shape[-1]
    flat = idx.reshape(b, 1, n * k).expand(b, c, n * k)
    return feat.gather(2, flat).reshape(b, c, n, k)


class NeighbourEmbedding(nn.Module):
    """One SG-style layer without sampling: edge features (f_j - f_i, f_i) of the k neighbours -> LBR
    -> max over the neighbourhood.

    The linear map W = [W_e, W_c] of the edge feature is applied before the neighbours are gathered:
    W (f_j - f_i, f_i) = (W_e f)_j + ((W_c - W_e) f)_i, so the products run over the n points rather
    than the n * k edges (k times fewer; the same result up to float rounding, the same parameters).
    ``mlp[0]`` only holds W (its own ``forward`` is not called), so checkpoints keep their keys.
    """

    def __init__(self, channels: int) -> None:
        super().__init__()
        self.mlp = nn.Sequential(
            PointwiseConv2d(2 * channels, channels, bias=False), nn.BatchNorm2d(channels),
            nn.ReLU(inplace=True),
        )

    def forward(self, feat: torch.Tensor, idx: torch.Tensor) -> torch.Tensor:
        linear, norm, act = self.mlp
        c = feat.shape[1]
        w = linear.weight[:, :, 0, 0]
        w_edge, w_centre = w[:, :c], w[:, c:]
        if not self.training:
            return self._forward_folded(feat, idx, w_edge, w_centre)
        edge = gather_neighbours(torch.matmul(w_edge, feat), idx)  # (B, C_out, n, k)
        centre = torch.matmul(w_centre - w_edge, feat).unsqueeze(-1)  # (B, C_out, n, 1)
        return act(norm(edge + centre)).amax(dim=-1)

    def _forward_folded(self, feat: torch.Tensor, idx: torch.Tensor, w_edge: torch.Tensor,
                        w_centre: torch.Tensor) -> torch.Tensor:
        """Eval mode: the BatchNorm is the affine map a x + b (running statistics), folded into the
        weights; the centre term and the shift are constant over the k neighbours, and ReLU is
        monotone, so max_j ReLU(a E_j + C) = ReLU(max_j (a E_j) + C): only the gather and the max run
        over the n * k edges (the normalisation, the addition and the ReLU run over n points)."""
        norm = self.mlp[1]
        scale = norm.weight / torch.sqrt(norm.running_var + norm.eps)
        shift = norm.bias - scale * norm.running_mean
        edge = gather_neighbours(torch.matmul(scale[:, None] * w_edge, feat), idx)  # (B, C_out, n, k)
        centre = torch.matmul(scale[:, None] * (w_centre - w_edge), feat) + shift[:, None]  # (B, C_out, n)
        return torch.relu(edge.amax(dim=-1) + centre)


class OffsetAttention(nn.Module):
    """PCT offset-attention: A = softmax(Q K^T) then L1-normalised over the other dim,
    F_sa = V A, output = LBR(F_in - F_sa) + F_in. Query and key share weights, as in PCT."""

    def __init__(self, channels: int) -> None:
        super().__init__()
        self.qk = PointwiseConv1d(channels, channels // 4, bias=False)
        self.v = PointwiseConv1d(channels, channels)
        self.trans = PointwiseConv1d(channels, channels)
        self.norm = nn.BatchNorm1d(channels)
        self.act = nn.ReLU(inplace=True)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        q = self.qk(x)  # (B, C/4, n)
        energy = torch.bmm(q.transpose(1, 2), q)  # (B, n, n)
        attn = torch.softmax(energy, dim=-1)
        # The L1 normalisation divides column j of A by its sum s_j, so V A = (V softmax) / s: dividing
        # the (C, n) product instead of the (n, n) matrix is the same up to float rounding.
        col_sum = 1e-9 + attn.sum(dim=1, keepdim=True)  # (B, 1, n)
        f_sa = torch.bmm(self.v(x), attn) / col_sum  # (B, C, n)
        return x + self.act(self.norm(self.trans(x - f_sa)))


class PCTEncoder(nn.Module):
    """Points (B, n, 3) -> per-point features (B, n, 4*d_e) and global feature (B, 2*4*d_e)."""

    def __init__(self, embed_dim: int, knn_k: int, neighbor_layers: int = 1) -> None:
        super().__init__()
        d = embed_dim
        self.knn_k = knn_k
        self.input_embedding = nn.Sequential(
            PointwiseConv1d(3, d, bias=False), nn.BatchNorm1d(d), nn.ReLU(inplace=True),
            PointwiseConv1d(d, d, bias=False), nn.BatchNorm1d(d), nn.ReLU(inplace=True),
        )
        self.neighbour = nn.ModuleList(NeighbourEmbedding(d) for _ in range(neighbor_layers))
        self.attention = nn.ModuleList(OffsetAttention(d) for _ in range(4))
        self.fuse = nn.Sequential(PointwiseConv1d(4 * d, 4 * d, bias=False), nn.BatchNorm1d(4 * d),
                                  nn.LeakyReLU(0.2, inplace=True))
        self.point_dim = 4 * d
        self.global_dim = 8 * d

    def forward(self, xyz: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        x = self.input_embedding(xyz.transpose(1, 2))
        if len(self.neighbour):
            idx = knn_indices(xyz, min(self.knn_k, xyz.shape[1]))
            for layer in self.neighbour:
                x = layer(x, idx)
        outs = []
        for layer in self.attention:
            x = layer(x)
            outs.append(x)
        per_point = torch.cat(outs, dim=1)  # (B, 4d, n)
        fused = self.fuse(per_point)
        global_feat = torch.cat([fused.amax(dim=-1), fused.mean(dim=-1)], dim=1)
        return per_point.transpose(1, 2), global_feat
