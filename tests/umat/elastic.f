C     Plane-strain (or 3-D) isotropic linear elasticity as an Abaqus UMAT, for pfem-mpi's tests:
C     PROPS(1) = E, PROPS(2) = nu. The stress increment is DDSDDE * DSTRAN (engineering shear).
C     With NSTATV = 7 it records where and when it was called, for the test of the interface:
C     NOEL, NPT, COORDS(1), COORDS(2), CELENT, KINC, TIME(1) + DTIME.
      SUBROUTINE UMAT(STRESS,STATEV,DDSDDE,SSE,SPD,SCD,
     1 RPL,DDSDDT,DRPLDE,DRPLDT,
     2 STRAN,DSTRAN,TIME,DTIME,TEMP,DTEMP,PREDEF,DPRED,CMNAME,
     3 NDI,NSHR,NTENS,NSTATV,PROPS,NPROPS,COORDS,DROT,PNEWDT,
     4 CELENT,DFGRD0,DFGRD1,NOEL,NPT,LAYER,KSPT,KSTEP,KINC)
      IMPLICIT NONE
      CHARACTER*80 CMNAME
      INTEGER NDI,NSHR,NTENS,NSTATV,NPROPS,NOEL,NPT,LAYER,KSPT
      INTEGER KSTEP,KINC,I,J
      DOUBLE PRECISION STRESS(NTENS),STATEV(*),DDSDDE(NTENS,NTENS),
     1 SSE,SPD,SCD,RPL,DDSDDT(NTENS),DRPLDE(NTENS),DRPLDT,
     2 STRAN(NTENS),DSTRAN(NTENS),TIME(2),DTIME,TEMP,DTEMP,
     3 PREDEF(1),DPRED(1),PROPS(NPROPS),COORDS(3),DROT(3,3),
     4 PNEWDT,CELENT,DFGRD0(3,3),DFGRD1(3,3)
      DOUBLE PRECISION E,NU,LAM,G
      E = PROPS(1)
      NU = PROPS(2)
      LAM = E*NU/((1.D0+NU)*(1.D0-2.D0*NU))
      G = E/(2.D0*(1.D0+NU))
      DO I = 1, NTENS
        DO J = 1, NTENS
          DDSDDE(I,J) = 0.D0
        END DO
      END DO
      DO I = 1, NDI
        DO J = 1, NDI
          DDSDDE(I,J) = LAM
        END DO
        DDSDDE(I,I) = LAM + 2.D0*G
      END DO
      DO I = NDI+1, NTENS
        DDSDDE(I,I) = G
      END DO
      DO I = 1, NTENS
        DO J = 1, NTENS
          STRESS(I) = STRESS(I) + DDSDDE(I,J)*DSTRAN(J)
        END DO
      END DO
      IF (NSTATV .GE. 7) THEN
        STATEV(1) = NOEL
        STATEV(2) = NPT
        STATEV(3) = COORDS(1)
        STATEV(4) = COORDS(2)
        STATEV(5) = CELENT
        STATEV(6) = KINC
        STATEV(7) = TIME(1) + DTIME
      END IF
      RETURN
      END
