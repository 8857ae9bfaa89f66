Merge "/work/main/build/tests/config_runs/out/wing_symmetry_hybrid/wing_symmetry_hybrid.msh";
Plugin(AnalyseMeshQuality).JacobianDeterminant=1;
Plugin(AnalyseMeshQuality).DimensionOfElements=3;
Plugin(AnalyseMeshQuality).Recompute=1;
Plugin(AnalyseMeshQuality).Run;
