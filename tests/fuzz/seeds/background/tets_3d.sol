MeshVersionFormatted 2
Dimension 3
SolAtVertices
5
1 3
1 0 1 0 0 1
2 0.5 1 0 0 1
1 0 2 0 0 1
1 0 1 0.5 0 3
1 0 1 0 0 1
End
