"""The scan matcher's 3 x 3 window minimum in explicit 4-wide vector code (numba intrinsic, LLVM IR).

numba compiles the window search of :func:`~slamtrials.slam.gmapping.kernels.score_pose` to scalar code
(one float per load, convert, subtract, multiply); its loads are not contiguous enough for LLVM to
vectorize them by itself. Here each window row (three cells, six float32: ``x0 y0 x1 y1 x2 y2``) is
read with two vector loads and the three squared distances are computed in one 4-lane vector (lane 3
repeats lane 2, so it cannot change the minimum). Every lane does exactly the scalar code's IEEE
operations, in the same order, and a minimum is exact whatever the order, so the result equals the
scalar window's bit for bit (tests/slam/gmapping/test_window.py).
"""

from __future__ import annotations

from llvmlite import ir
from numba import types
from numba.core.extending import intrinsic

__all__ = ["window_min_3x3"]

_F32 = ir.FloatType()
_F64 = ir.DoubleType()
_I32 = ir.IntType(32)
_V4D = ir.VectorType(_F64, 4)
#: What the window gives when all its cells are empty (the scalar code's starting value).
NOTHING_D2 = 1.0e36


def _shuffle(builder: ir.IRBuilder, a: ir.Value, b: ir.Value, lanes: tuple[int, ...]) -> ir.Value:
    return builder.shuffle_vector(a, b, ir.Constant(ir.VectorType(_I32, len(lanes)), list(lanes)))


def _splat(builder: ir.IRBuilder, value: ir.Value) -> ir.Value:
    vector = builder.insert_element(ir.Constant(_V4D, ir.Undefined), value, ir.Constant(_I32, 0))
    return _shuffle(builder, vector, vector, (0, 0, 0, 0))


def _min(builder: ir.IRBuilder, a: ir.Value, b: ir.Value) -> ir.Value:
    """``b if b < a else a``, lane by lane (the scalar code's ``min(a, b)``)."""
    return builder.select(builder.fcmp_ordered("<", b, a), b, a)


def _load(builder: ir.IRBuilder, data: ir.Value, index: ir.Value, lanes: int) -> ir.Value:
    """``lanes`` float32 from ``data[index]`` on, widened to float64."""
    pointer = builder.gep(data, [index], inbounds=True)
    vector = builder.load(builder.bitcast(pointer, ir.VectorType(_F32, lanes).as_pointer()), align=4)
    return builder.fpext(vector, ir.VectorType(_F64, lanes))


@intrinsic
def window_min_3x3(typingctx, mean, first, row_stride, ox, oy, res):  # pragma: no cover - compiled
    """Smallest squared distance from a beam's endpoint to the means of a 3 x 3 window of cells.

    Call from numba code as ``window_min_3x3(mean, first, row_stride, ox, oy, res)``:

    mean:
        float32 C-contiguous ``[M]``, the pool's mean offsets flattened (``kernels`` module docstring).
    first:
        int64 index in ``mean`` of the window's lower-left cell's x; the window's row ``dr`` starts at
        ``first + dr * row_stride``, its cells at steps of 2. All 18 values must lie inside ``mean``.
    ox, oy:
        float64 offset of the endpoint from the lower-left corner of the window's centre cell (m).
    res:
        float64 cell size (m).

    Returns float64 ``min(NOTHING_D2, min over dr, dc of |(ox - (dc - 1) res - mx, oy - (dr - 1) res -
    my)|^2)``: what the scalar loop of ``score_pose`` computes, bit for bit.
    """
    signature = types.float64(mean, first, row_stride, ox, oy, res)

    def codegen(context, builder, sig, args):
        mean_value, first_value, stride_value, ox_value, oy_value, res_value = args
        data = context.make_array(sig.args[0])(context, builder, value=mean_value).data
        # ox - (dc - 1) * res for dc = 0, 1, 2 (and 2 again in lane 3)
        column_steps = ir.Constant(_V4D, [-1.0, 0.0, 1.0, 1.0])
        ox_lanes = builder.fsub(_splat(builder, ox_value), builder.fmul(column_steps, _splat(builder, res_value)))
        best = None
        for dr in range(3):
            start = builder.add(first_value, builder.mul(stride_value, ir.Constant(first_value.type, dr)))
            head = _load(builder, data, start, 4)  # x0 y0 x1 y1
            tail = _load(builder, data, builder.add(start, ir.Constant(start.type, 4)), 2)  # x2 y2
            tail = _shuffle(builder, tail, tail, (0, 1, 0, 1))
            xs = _shuffle(builder, head, tail, (0, 2, 4, 4))
            ys = _shuffle(builder, head, tail, (1, 3, 5, 5))
            uy0 = builder.fsub(oy_value, builder.fmul(ir.Constant(_F64, float(dr - 1)), res_value))
            ux = builder.fsub(ox_lanes, xs)
            uy = builder.fsub(_splat(builder, uy0), ys)
            d2 = builder.fadd(builder.fmul(ux, ux), builder.fmul(uy, uy))
            best = d2 if best is None else _min(builder, best, d2)
        best = _min(builder, best, _shuffle(builder, best, best, (2, 3, 0, 1)))
        best = _min(builder, best, _shuffle(builder, best, best, (1, 0, 3, 2)))
        lowest = builder.extract_element(best, ir.Constant(_I32, 0))
        return _min(builder, ir.Constant(_F64, NOTHING_D2), lowest)

    return signature, codegen
