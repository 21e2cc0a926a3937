"""The names of RAPID's instructions and functions (RobotWare 6 / 7 reference manual), implemented
here or not. A name on these lists that rapid_like does not implement is reported as what it is, a
RAPID instruction or function this interpreter lacks, never with a "did you mean" guess: a robot
programmer who wrote `GetMotorTorque` meant it.
"""
from __future__ import annotations

INSTRUCTIONS = frozenset(name.lower() for name in """
AccSet ActEventBuffer ActUnit Add AliasCamera AliasIO AliasIOReset BitClear BitSet BookErrNo Break
CallByVar CamFlush CamGetParameter CamGetResult CamLoadJob CamReqImage CamSetExposure CamSetParameter
CamSetProgramMode CamSetRunMode CamStartLoadJob CamWaitLoadJob CancelLoad CheckProgRef CirPathMode Clear
ClearIOBuff ClearPath ClearRawBytes ClkReset ClkStart ClkStop Close CloseDir ConfJ ConfL CONNECT ContactL
CopyFile CopyRawBytes CorrClear CorrCon CorrDiscon CorrWrite DeactEventBuffer DeactUnit Decr DitherAct
DitherDeact DropSensor DropWObj EGMActJoint EGMActMove EGMActPose EGMGetId EGMMoveC EGMMoveL EGMReset
EGMRunJoint EGMRunPose EGMSetupAI EGMSetupAO EGMSetupGI EGMSetupLTAPP EGMSetupUC EGMStop EOffsOff EOffsOn
EOffsSet EraseModule ErrLog ErrRaise ErrWrite EXIT ExitCycle FitCircle FricIdInit FricIdEvaluate FricIdSetFricLevels
GetDataVal GetJointData GetSysData GetTrapData GripLoad HollowWristReset IDelete IDisable IEnable IError
IndAMove IndCMove IndDMove IndReset IndRMove InvertDO IOBusStart IODisable IOEnable IPers IRMQMessage
ISignalAI ISignalAO ISignalDI ISignalDO ISignalGI ISignalGO ISleep ITimer IVarValue IWatch Load LoadId
MakeDir ManLoadIdProc MechUnitLoad MotionProcessModeSet MotionSup MoveAbsJ MoveAbsJDO MoveAbsJGO
MoveAbsJSync MoveC MoveCAO MoveCDO MoveCGO MoveCSync MoveExtJ MoveJ MoveJAO MoveJDO MoveJGO MoveJSync
MoveL MoveLAO MoveLDO MoveLGO MoveLSync MToolRotCalib MToolTCPCalib Open OpenDir PackDNHeader PackRawBytes
PathAccLim PathRecMoveBwd PathRecMoveFwd PathRecStart PathRecStop PathResol PDispOff PDispOn PDispSet
ProcCall ProcerrRecovery PrxActivAndStoreRecord PrxActivRecord PrxDbgStoreRecord PrxDeactRecord
PrxResetPos PrxResetRecords PrxSetPosOffset PrxSetRecordSampleTime PrxSetSyncalarm PrxStartRecord
PrxStopRecord PrxStoreRecord PrxUseFileRecord PulseDO RAISE RaiseToUser ReadAnyBin ReadBlock ReadCfgData
ReadErrData ReadRawBytes RemoveAllCyclicBool RemoveCyclicBool RemoveDir RemoveFile RenameFile Reset
ResetAxisDistance ResetAxisMoveTime ResetPPMoved ResetRetryCount RestoPath RETRY RETURN Rewind
RMQEmptyQueue RMQFindSlot RMQGetMessage RMQGetMsgData RMQGetMsgHeader RMQReadWait RMQSendMessage
RMQSendWait SafetyControllerSyncRequest Save SaveCfgData SCWrite SearchC SearchExtJ SearchL SecondaryCamSel
SenDevice Set SetAllDataVal SetAO SetDataSearch SetDataVal SetDO SetGO SetLeadThrough SetSysData
SetupCyclicBool SiConnect SiClose SiGetCyclic SingArea SiSetCyclic SkipWarn SocketAccept SocketBind
SocketClose SocketConnect SocketCreate SocketListen SocketReceive SocketReceiveFrom SocketSend
SocketSendTo SoftAct SoftDeact SpeedLimAxis SpeedLimCheckPoint SpeedRefresh SpyStart SpyStop StartLoad
StartMove StartMoveRetry STCalib STCalc STClose StepBwdPath STIndGun STIndGunReset SToolRotCalib
SToolTCPCalib Stop STOpen StopMove StopMoveReset StorePath STTune STTuneReset SupSyncSensorOff
SupSyncSensorOn SyncMoveOff SyncMoveOn SyncMoveResume SyncMoveSuspend SyncMoveUndo SyncToSensor
SystemStopAction TEST TestSignDefine TestSignReset TextTabInstall TPErase TPReadDnum TPReadFK TPReadNum
TPShow TPWrite TriggAInt TriggC TriggCheckIO TriggDataCopy TriggDataReset TriggEquip TriggInt TriggIO
TriggJ TriggJIOs TriggL TriggLIOs TriggRampAO TriggSpeed TriggStopProc TryInt TuneReset TuneServo
UIMsgBox UIShow UnLoad UnpackRawBytes VelSet WaitAI WaitAO WaitDI WaitDO WaitGI WaitGO WaitLoad
WaitRob WaitSensor WaitSyncTask WaitTestAndSet WaitTime WaitUntil WaitWObj WarmStart WorldAccLim Write
WriteAnyBin WriteBin WriteBlock WriteCfgData WriteRawBytes WriteStrBin WriteVar WZBoxDef WZCylDef
WZDisable WZDOSet WZEnable WZFree WZHomeJointDef WZLimJointDef WZLimSup WZSphDef WZEnable
""".split())

FUNCTIONS = frozenset(name.lower() for name in """
Abs AbsDnum ACos ACosDnum AInput AND AOutput ArgName ASin ASinDnum ATan ATan2 ATan2Dnum ATanDnum BitAnd
BitAndDnum BitCheck BitCheckDnum BitLSh BitLShDnum BitNeg BitNegDnum BitOr BitOrDnum BitRSh BitRShDnum
BitXOr BitXOrDnum ByteToStr CalcJointT CalcRobT CalcRotAxFrameZ CalcRotAxisFrame CamGetExposure
CamGetLoadedJob CamGetName CamNumberOfResults CDate CJointT ClkRead CorrRead Cos CosDnum CPos CRobT
CSpeedOverride CTime CTool CWObj DecToHex DefAccFrame DefDFrame DefFrame Dim DInput Distance DnumToNum
DnumToStr DotProd DOutput EGMGetState EulerZYX EventType ExecHandler ExecLevel Exp FileSize FileTime
FSSize GetMaxNumberOfCyclicBool GetMecUnitName GetModalPayLoadMode GetMotorTorque GetNextCyclicBool
GetNextMechUnit GetNextSym GetNumberOfCyclicBool GetServiceInfo GetSignalOrigin GetSysInfo GetTaskName
GetTime GetTSPStatus GetUASUserName GInput GInputDnum GOutput GOutputDnum HexToDec IndInpos IndSpeed
IOUnitState IsBrakeCheckActive IsCyclicBool IsFile IsLeadThrough IsMechUnitActive IsPers IsStopMoveAct
IsStopStateEvent IsSyncMoveOn IsSysId IsVar MaxExtLinearSpeed MaxExtReorientSpeed MaxRobReorientSpeed
MaxRobSpeed MirPos ModExist ModTime MotionPlannerNo NonMotionMode NOrient NumToDnum NumToStr Offs OpMode
OrientZYX ORobT ParIdPosValid ParIdRobValid PathLevel PathRecValidBwd PathRecValidFwd PFRestart PoseInv
PoseMult PoseVect Pow PowDnum PPMovedInManMode Present ProgMemFree PrxGetMaxRecordpos RawBytesLen ReadBin
ReadDir ReadMotor ReadNum ReadStr ReadStrBin ReadVar RelTool RemainingRetries RMQGetSlotName RobName
RobOS Round RoundDnum RunMode SafetyControllerGetChecksum SafetyControllerGetSWVersion
SafetyControllerGetUserChecksum Sin SinDnum SocketGetStatus SocketPeek Sqrt SqrtDnum STCalcForce
STCalcTorque STIsCalib STIsClosed STIsIndGun STIsOpen StrDigCalc StrDigCmp StrFind StrFormat StrLen
StrMap StrMatch StrMemb StrOrder StrPart StrToByte StrToVal Tan TanDnum TaskRunMec TaskRunRob TaskRunMec
TaskIsActive TaskIsExecuting TasksInSync TestAndSet TestDI TestSignRead TextGet TextTabFreeToUse
TextTabGet TriggDataValid Trunc TruncDnum Type UIAlphaEntry UIClientExist UIDnumEntry UIDnumTune
UIListView UIMessageBox UINumEntry UINumTune ValidIO ValToStr VectMagn
""".split())

PREDEFINED_DATA = frozenset(name.lower() for name in """
ERR_ACC_TOO_LOW ERR_ACTIV_PROF ERR_ADDR_INUSE ERR_ALIASIO_DEF ERR_ALIASIO_TYPE ERR_ALRDY_MOVING
ERR_AO_LIM ERR_ARGDUPCND ERR_ARGNAME ERR_ARGNOTPER ERR_ARGVALERR ERR_ARRAY_SIZE ERR_AXIS_ACT
ERR_AXIS_IND ERR_AXIS_MOVING ERR_AXIS_PAR ERR_BUSSTATE ERR_BWDLIMIT ERR_CALC_NEG ERR_CALLPROC
ERR_CAM_BUSY ERR_CFG_INTERNAL ERR_CFG_LIMIT ERR_CNTNOTVAR ERR_CNV_NOT_ACT ERR_COLL_STOP
ERR_COMM_EXT ERR_DATA_RECV ERR_DEV_MAXTIME ERR_DIPLAG_LIM ERR_DIVZERO ERR_EXECPHR ERR_FILEACC
ERR_FILEEXIST ERR_FILEOPEN ERR_FILNOTFND ERR_FNCNORET ERR_FRAME ERR_GO_LIM ERR_INOISSAFE ERR_INOMAX
ERR_INT_MAXVAL ERR_INT_NOTVAL ERR_INVDIM ERR_IODISABLE ERR_IODN_TIMEOUT ERR_IOENABLE ERR_IOERROR
ERR_LOADID_FATAL ERR_LOADID_RETRY ERR_MAXINTVAL ERR_MODULE ERR_MOD_NOT_LOADED ERR_MOD_NOTLOADED
ERR_MSG_PENDING ERR_NAME_INVALID ERR_NORUNUNIT ERR_NOT_MOVETASK ERR_NOTARR ERR_NOTEQDIM ERR_NOTINTVAL
ERR_NOTPRES ERR_NOTSAVED ERR_NUM_LIMIT ERR_OUTOFBND ERR_OVERFLOW ERR_PATH ERR_PATH_STOP ERR_PATHDIST
ERR_PID_MOVESTOP ERR_PID_RAISE_PP ERR_PRGMEMFULL ERR_PROCSIGNAL_OFF ERR_PROGSTOP ERR_RANYBIN_CHK
ERR_RANYBIN_EOF ERR_RCVDATA ERR_REFUNKDAT ERR_REFUNKFUN ERR_REFUNKPRC ERR_REFUNKTRP ERR_RMQ_DIM
ERR_RMQ_FULL ERR_RMQ_INVALID ERR_RMQ_INVMSG ERR_RMQ_MSGSIZE ERR_RMQ_NAME ERR_RMQ_NOMSG ERR_RMQ_TIMEOUT
ERR_RMQ_VALUE ERR_ROBLIMIT ERR_SC_WRITE ERR_SIG_NAME ERR_SIGSUPSEARCH ERR_SOCK_ADDR_INUSE
ERR_SOCK_CLOSED ERR_SOCK_NET_UNREACH ERR_SOCK_TIMEOUT ERR_SPEED_REFRESH_LIM ERR_STARTMOVE ERR_STORE_PROF
ERR_STRTOOLNG ERR_SYM_ACCESS ERR_SYMBOL_TYPE ERR_SYNCMOVEOFF ERR_SYNCMOVEON ERR_SYNTAX ERR_TASKNAME
ERR_TP_DIBREAK ERR_TP_DOBREAK ERR_TP_MAXTIME ERR_TP_NO_CLIENT ERR_TRUSTLEVEL ERR_TXTNOEXIST ERR_UI_INITVALUE
ERR_UI_MAX ERR_UI_MIN ERR_UI_NOTINT ERR_UISHOW_FATAL ERR_UISHOW_FULL ERR_UNIT_PAR ERR_UNKINO ERR_UNKPROC
ERR_UNLOAD ERR_USE_PROF ERR_WAIT_MAXTIME ERR_WHLSEARCH ERR_WOBJ_MOVING
""".split())


def kind_of(name: str) -> str | None:
    """"instruction" or "function" for a RAPID name, None for a name RAPID does not define."""
    key = name.lower()
    if key in INSTRUCTIONS:
        return "instruction"
    if key in FUNCTIONS:
        return "function"
    if key in PREDEFINED_DATA:
        return "data"
    return None


# RobotWare options the twin cannot honour: a program using them is refused where it names them, with the
# option's name, never run wrongly. (Instructions, functions and data types alike.)
_OPTIONS = {
    "EGM (Externally Guided Motion)": ("an external computer steers the real controller's motion at 4 ms; the "
                                       "twin's planner has no such input",
                                       "egm"),
    "arc welding (Arc, RobotWare Arc option)": ("welding equipment, seam tracking and weaving are not simulated",
                                                "arcl arcc arclstart arclend arccstart arccend arcl1 arcl2 arcc1 arcc2 "
                                                "arcrefresh arckill arcmoveextj seamdata welddata weavedata trackdata "
                                                "arcdata advseamdata"),
    "SmarTac (touch sensing)": ("touch sensing needs the real torch and work piece",
                                "search_1d search_groove search_part search_ext smartac smartacdata"),
    "MultiMove": ("rapid_like runs one motion task, so there is no other robot to move with",
                  "syncmoveon syncmoveoff syncmoveundo syncmovesuspend syncmoveresume issyncmoveon moveextj "
                  "searchextj"),
}
_OPTION_OF = {word: option for option, (_, words) in _OPTIONS.items() for word in words.split() if word != "egm"}


def refused(name: str) -> str | None:
    """Why `name` (an instruction, function or data type of a RobotWare option the twin cannot honour) is refused,
    or None."""
    key = name.lower()
    option = "EGM (Externally Guided Motion)" if key.startswith("egm") else _OPTION_OF.get(key)
    if option is None:
        return None
    return f"{name} belongs to {option}, which the twin cannot honour: {_OPTIONS[option][0]}"
