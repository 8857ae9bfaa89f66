MeshVersionFormatted 2
Dimension 2
SolAtVertices
4
1 3
1 0 1
2 0.5 1
1 0 2
3 -1 1
End
