! Socket messaging over real TCP on loopback, server and client in one program: the connection
! completes in the listen backlog, SocketAccept takes it; a string one way, packed rawbytes back;
! a peer that closes is ERR_SOCK_CLOSED at the next SocketReceive.
! trace: {"t": 0.0, "type": "socket", "event": "connected", "address": "127.0.0.1", "port": 47813}
! trace: {"t": 0.0, "type": "socket", "event": "accepted", "address": "127.0.0.1"}
! trace: {"t": 0.0, "type": "print", "text": "connected TRUE"}
! trace: {"t": 0.0, "type": "print", "text": "peer got hello robot"}
! trace: {"t": 0.0, "type": "print", "text": "client got 6 bytes: 258 1.5"}
! trace: {"t": 0.0, "type": "print", "text": "closed by peer"}
! trace: {"t": 0.0, "type": "print", "text": "closed TRUE"}
! trace: {"t": 0.0, "type": "end", "reason": "completed"}
MODULE Sockets
  VAR socketdev server;
  VAR socketdev client;
  VAR socketdev peer;
  VAR string received;
  VAR rawbytes raw;
  VAR num len;
  PROC main()
    SocketCreate server;
    SocketBind server, "127.0.0.1", 47813;
    SocketListen server;
    SocketCreate client;
    SocketConnect client, "127.0.0.1", 47813;
    SocketAccept server, peer;
    TPWrite "connected " + ValToStr(SocketGetStatus(client) = SOCKET_CONNECTED);
    SocketSend client \Str:="hello robot";
    SocketReceive peer \Str:=received;
    TPWrite "peer got " + received;
    PackRawBytes 258, raw, 1, \IntX:=UINT;
    PackRawBytes 1.5, raw, 3, \Float4;
    SocketSend peer \RawData:=raw;
    ClearRawBytes raw;
    SocketReceive client \RawData:=raw \ReadNoOfBytes:=6 \NoRecBytes:=len;
    UnpackRawBytes raw, 1, reg1, \IntX:=UINT;
    UnpackRawBytes raw, 3, reg2, \Float4;
    TPWrite "client got " + ValToStr(len) + " bytes: " + ValToStr(reg1) + " " + ValToStr(reg2);
    SocketClose peer;
    SocketReceive client \Str:=received \Time:=1;
    TPWrite "not reached";
  ERROR
    IF ERRNO = ERR_SOCK_CLOSED THEN
      TPWrite "closed by peer";
      SocketClose client;
      SocketClose server;
      TPWrite "closed " + ValToStr(SocketGetStatus(client) = SOCKET_CLOSED);
      RETURN;
    ENDIF
  ENDPROC
ENDMODULE
