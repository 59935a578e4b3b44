"""Dependency order of components: Kahn's topological sort over direct-feedthrough edges."""
import heapq


def toposort(n, edges):
    """Order of nodes 0..n-1 along `edges` (pairs p -> c), ties by index.

    Returns (order, None), or (partial order, cycle as a node list [a, b, ..., a])."""
    succ = [[] for _ in range(n)]
    indeg = [0] * n
    for (p, c) in edges:
        if p == c:
            return [], [p, p]
        succ[p].append(c)
        indeg[c] += 1
    heap = [i for i in range(n) if indeg[i] == 0]
    heapq.heapify(heap)
    order = []
    while heap:
        i = heapq.heappop(heap)
        order.append(i)
        for c in succ[i]:
            indeg[c] -= 1
            if indeg[c] == 0:
                heapq.heappush(heap, c)
    if len(order) == n:
        return order, None
    # find one cycle among the remaining nodes
    remaining = {i for i in range(n) if indeg[i] > 0}
    start = min(remaining)
    path, seen = [start], {start: 0}
    node = start
    while True:
        nxt = next(c for c in succ[node] if c in remaining)
        if nxt in seen:
            return order, path[seen[nxt]:] + [nxt]
        seen[nxt] = len(path)
        path.append(nxt)
        node = nxt
