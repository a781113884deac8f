# The STOP record moves to the cobots app (hrc.cobots.models.CellStop), which keeps
# this app's table: only the state is deleted here, never the table.

from django.db import migrations


class Migration(migrations.Migration):

    dependencies = [
        ('live', '0001_initial'),
        ('cobots', '0008_cellstop_from_live'),
    ]

    operations = [
        migrations.SeparateDatabaseAndState(
            state_operations=[migrations.DeleteModel(name='CellStop')],
            database_operations=[],
        ),
    ]
