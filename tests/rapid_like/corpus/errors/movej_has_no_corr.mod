! MoveJ has no \Corr in the RAPID manual (path correction is for MoveL and MoveC).
! error: 7:32 MoveJ: no optional argument \Corr
! exit: 65
MODULE NoCorr
  CONST robtarget p := [[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    MoveJ p, v100, fine, tool0 \Corr;
  ENDPROC
ENDMODULE
