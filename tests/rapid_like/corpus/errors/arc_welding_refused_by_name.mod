! Arc welding instructions are refused by name at their position (never run as a plain MoveL).
! error: 7:5 ArcLStart belongs to arc welding (Arc, RobotWare Arc option), which the twin cannot honour
! exit: 65
MODULE Weld
  CONST robtarget p := [[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];
  PROC main()
    ArcLStart p, v100, seam1, weld1, fine, tool0;
  ENDPROC
ENDMODULE
