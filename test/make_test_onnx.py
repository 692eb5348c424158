#!/usr/bin/python3
"""Writes two small ONNX models whose outputs are known, for the ONNX path of camera_detector
(OnnxPersonDetector, cv::dnn::readNetFromONNX). Needs Debian's python3-onnx; nothing is downloaded.

  person_ssd.onnx   input [1, 3, H, W]; output [1, 1, 2, 7] in the layout of OpenCV's DetectionOutput layer
                    (image, class, score, x1, y1, x2, y2; corners normalised to [0, 1]):
                      row 0: class 1 (person), score = the mean of the input blob, box (0.1, 0.2)-(0.4, 0.9)
                      row 1: class 2 (not a person), score 0.99, box (0.5, 0.5)-(0.6, 0.6)
                    The score depends on the input, so a test checks the preprocessing too: a uniform image
                    of value v gives the blob value (v - mean) * scale everywhere.
  wrong_shape.onnx  same input; output [1, 1, 1, 5] (rows of 5, not 7): the detector must refuse it with a clear
                    error.

Usage: make_test_onnx.py OUT_DIR [H=300] [W=300]"""
import os
import sys

import numpy as np
from onnx import TensorProto, checker, helper, numpy_helper, save


def const(name, values):
    return numpy_helper.from_array(np.asarray(values, dtype=np.float32), name)


def model(nodes, inits, out_shape, h, w, name):
    graph = helper.make_graph(
        nodes, name,
        [helper.make_tensor_value_info("input", TensorProto.FLOAT, [1, 3, h, w])],
        [helper.make_tensor_value_info("detections", TensorProto.FLOAT, out_shape)],
        initializer=inits)
    m = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 11)], producer_name="picker_localisation")
    m.ir_version = 6
    checker.check_model(m)
    return m


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    h = int(sys.argv[2]) if len(sys.argv) > 2 else 300
    w = int(sys.argv[3]) if len(sys.argv) > 3 else 300
    os.makedirs(out, exist_ok=True)
    mean = helper.make_node("ReduceMean", ["input"], ["score"], axes=[1, 2, 3], keepdims=1)  # [1, 1, 1, 1]
    person = [
        mean,
        helper.make_node("Concat", ["head", "score", "box"], ["row0"], axis=3),       # [1, 1, 1, 7]
        helper.make_node("Concat", ["row0", "other"], ["detections"], axis=2),       # [1, 1, 2, 7]
    ]
    inits = [
        const("head", [[[[0.0, 1.0]]]]),
        const("box", [[[[0.1, 0.2, 0.4, 0.9]]]]),
        const("other", [[[[0.0, 2.0, 0.99, 0.5, 0.5, 0.6, 0.6]]]]),
    ]
    save(model(person, inits, [1, 1, 2, 7], h, w, "person_ssd"), os.path.join(out, "person_ssd.onnx"))
    wrong = [mean, helper.make_node("Concat", ["head", "score", "short"], ["detections"], axis=3)]  # [1, 1, 1, 5]
    save(model(wrong, [const("head", [[[[0.0, 1.0]]]]), const("short", [[[[0.1, 0.2]]]])], [1, 1, 1, 5], h, w,
               "wrong_shape"),
         os.path.join(out, "wrong_shape.onnx"))
    print("make_test_onnx: wrote person_ssd.onnx and wrong_shape.onnx to " + out)


if __name__ == "__main__":
    main()
