! Pose maths: PoseMult composes, PoseInv inverts, PoseVect maps a point; DefFrame builds a frame with
! its origin at P1, x towards P2 and P3 in the xy plane. p2 is 90 degrees about z, at y = 50.
! trace: {"t": 0.0, "type": "print", "text": "mult [[100,50,0],[0.707107,0,0,0.707107]]"}
! trace: {"t": 0.0, "type": "print", "text": "inv [[-50,0,0],[0.707107,0,0,-0.707107]]"}
! trace: {"t": 0.0, "type": "print", "text": "vect [0,60,0]"}
! trace: {"t": 0.0, "type": "print", "text": "frame [[10,20,0],[0.707107,0,0,0.707107]]"}
! trace: {"t": 0.0, "type": "print", "text": "magn 5 dot 11"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Poses
  VAR pose p1 := [[100, 0, 0], [1, 0, 0, 0]];
  VAR pose p2 := [[0, 50, 0], [0.7071068, 0, 0, 0.7071068]];
  CONST robtarget a := [[10, 20, 0], [1, 0, 0, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST robtarget b := [[10, 120, 0], [1, 0, 0, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  CONST robtarget c := [[-90, 20, 0], [1, 0, 0, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
  PROC main()
    TPWrite "mult " + ValToStr(PoseMult(p1, p2));
    TPWrite "inv " + ValToStr(PoseInv(p2));
    TPWrite "vect " + ValToStr(PoseVect(p2, [10, 0, 0]));
    TPWrite "frame " + ValToStr(DefFrame(a, b, c));
    TPWrite "magn " + ValToStr(VectMagn([3, 4, 0])) + " dot " + ValToStr(DotProd([1, 2, 3], [3, 1, 2]));
  ENDPROC
ENDMODULE
