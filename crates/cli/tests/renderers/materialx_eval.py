#!/usr/bin/env python3
"""Evaluates a MaterialX document's float node graph as MaterialX defines its nodes, in
float32, at given inputs: an independent reading of what specula wrote.

    python materialx_eval.py DOC.mtlx NODEDEF --t T [T ...] [--input NAME=VALUE ...]

Prints one value per `t`. Knows the standard nodes specula's lobe graphs use; any other node
is an error naming it.
"""

import argparse
import sys

import numpy as np
import MaterialX as mx

F = np.float32

# Each standard node as MaterialX's specification defines it (inputs by name).
NODES = {
    "add": lambda i: i["in1"] + i["in2"],
    "subtract": lambda i: i["in1"] - i["in2"],
    "multiply": lambda i: i["in1"] * i["in2"],
    "divide": lambda i: i["in1"] / i["in2"],
    "power": lambda i: np.power(i["in1"], i["in2"]),
    "ln": lambda i: np.log(i["in"]),
    "exp": lambda i: np.exp(i["in"]),
    "sqrt": lambda i: np.sqrt(i["in"]),
    "acos": lambda i: np.arccos(i["in"]),
    "cos": lambda i: np.cos(i["in"]),
    "ceil": lambda i: np.ceil(i["in"]),
    "min": lambda i: np.minimum(i["in1"], i["in2"]),
    "max": lambda i: np.maximum(i["in1"], i["in2"]),
    "clamp": lambda i: np.minimum(np.maximum(i["in"], i["low"]), i["high"]),
    "ifgreater": lambda i: np.where(i["value1"] > i["value2"], i["in1"], i["in2"]),
}


def evaluate(graph, interface):
    cache = {}

    def value_of(port):
        if port.getNodeName():
            return node_value(port.getNodeName())
        if port.getInterfaceName():
            return interface[port.getInterfaceName()]
        return F(port.getValue())

    def node_value(name):
        if name not in cache:
            node = graph.getNode(name)
            rule = NODES.get(node.getCategory())
            if rule is None:
                raise SystemExit("error: node %s is a %s, which this evaluator does not know"
                                 % (name, node.getCategory()))
            inputs = {port.getName(): value_of(port) for port in node.getInputs()}
            cache[name] = F(rule(inputs))
        return cache[name]

    return value_of(graph.getOutputs()[0])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("document")
    parser.add_argument("nodedef")
    parser.add_argument("--t", type=float, nargs="+", required=True)
    parser.add_argument("--input", action="append", default=[], metavar="NAME=VALUE")
    args = parser.parse_args()
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, args.document)
    nodedef = doc.getNodeDef(args.nodedef)
    if nodedef is None:
        raise SystemExit("error: no nodedef %s" % args.nodedef)
    graph = next(g for g in doc.getNodeGraphs() if g.getNodeDefString() == args.nodedef)
    defaults = {port.getName(): F(port.getValue()) for port in nodedef.getInputs()}
    for assignment in args.input:
        name, value = assignment.split("=", 1)
        defaults[name] = F(float(value))
    with np.errstate(all="ignore"):
        for t in args.t:
            interface = dict(defaults, t=F(t))
            print(repr(float(evaluate(graph, interface))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
